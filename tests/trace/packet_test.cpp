// Packets of up to eight rays (Bvh::closest8 / occluded8) give every ray exactly its single-ray result:
// t, barycentrics and triangle bit for bit, and the same shadow answer, on every ISA.
#include "trace/bvh.hpp"

#include <cstring>
#include <random>

#include <glm/geometric.hpp>

#include "core/camera.hpp"
#include "trace/procedural.hpp"

#include <gtest/gtest.h>

namespace rtr::trace {
namespace {

std::vector<Triangle> trianglesOf(const Mesh& m, glm::vec3 offset = glm::vec3(0.0f)) {
  std::vector<Triangle> tris;
  for (size_t i = 0; i < m.indices.size(); i += 3)
    tris.push_back(
        {m.positions[m.indices[i]] + offset, m.positions[m.indices[i + 1]] + offset, m.positions[m.indices[i + 2]] + offset});
  return tris;
}

// Every group of `width` consecutive rays as one packet against each ray alone, on every ISA, with leaves
// tested all rays at once wherever two or more rays reach them, and always ray by ray, closest hit as
// coherent and as scattered rays, with hand-offs to single rays from 0 (never) to 8 (at once) live rays;
// returns the number of hits (of the last pass) so callers can check the case is not vacuous.
size_t expectPacketsMatchSingles(const Bvh& bvh, const std::vector<Ray>& rays, int width = 8, const char* what = "") {
  size_t hits = 0;
  for (int pass = 0; pass < 6; ++pass) {
    const BvhIsa isa = pass % 3 == 0 ? BvhIsa::Avx512 : pass % 3 == 1 ? BvhIsa::Avx2 : BvhIsa::Sse;
    const int leafRays = pass < 3 ? 2 : 9;
    constexpr int kAlone[6][3] = {{4, 4, 4}, {1, 6, 2}, {0, 8, 4}, {8, 1, 0}, {2, 0, 8}, {6, 3, 1}};
    Bvh::setIsa(isa);
    Bvh::setPacketLeafRays(leafRays);
    Bvh::setPacketAloneRays(kAlone[pass][0], kAlone[pass][1], kAlone[pass][2]);
    hits = 0;
    for (size_t i = 0; i < rays.size(); i += width) {
      const int n = int(std::min<size_t>(width, rays.size() - i));
      Hit h[8], hs[8];
      bvh.closest8(&rays[i], n, h);
      bvh.closest8(&rays[i], n, hs, IntersectMethod::Watertight, PacketKind::Scattered);
      const unsigned occ = bvh.occluded8(&rays[i], n);
      for (int k = 0; k < n; ++k) {
        const Hit one = bvh.closest(rays[i + k]);
        const bool occ1 = bvh.occluded(rays[i + k]);
        const bool same = std::memcmp(&h[k], &one, sizeof one) == 0 && std::memcmp(&hs[k], &one, sizeof one) == 0;
        if (!same || (occ >> k & 1) != occ1) {
          ADD_FAILURE() << what << " " << Bvh::isaName(isa)
                        << (leafRays == 2 ? ", leaves all rays at once" : ", leaves ray by ray") << ", alone from "
                        << kAlone[pass][0] << "/" << kAlone[pass][1] << "/" << kAlone[pass][2] << ", ray " << i + k
                        << " of a packet of " << n << ": triangle " << h[k].prim << " t " << h[k].t << " b " << h[k].b1 << " "
                        << h[k].b2 << " (scattered: triangle " << hs[k].prim << " t " << hs[k].t << ") occluded "
                        << (occ >> k & 1) << "; alone: " << one.prim << " t " << one.t << " b " << one.b1 << " " << one.b2
                        << " occluded " << occ1;
          break;
        }
        hits += one.hit();
      }
      if (::testing::Test::HasFailure()) break;
    }
    if (::testing::Test::HasFailure()) break;
  }
  Bvh::setIsa(BvhIsa::Avx512);
  Bvh::setPacketLeafRays(Bvh::kPacketLeafRays);
  Bvh::setPacketAloneRays(Bvh::kPacketAloneRays[0], Bvh::kPacketAloneRays[1], Bvh::kPacketAloneRays[2]);
  return hits;
}

// Random packets mixing hits and misses, non-casters, short tMax, and partly degenerate packets: lanes
// with a zero direction, with tMax 0, or parallel to an axis the others are not (those go one by one).
TEST(Packets, RandomPacketsMixingHitsAndMisses) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Triangle> tris;
  std::vector<uint8_t> casts;
  for (int i = 0; i < 6000; ++i) {
    const glm::vec3 c{u(rng) * 10, u(rng) * 10, u(rng) * 10};
    tris.push_back({c, c + glm::vec3{u(rng), u(rng), u(rng)}, c + glm::vec3{u(rng), u(rng), u(rng)}});
    casts.push_back(i % 5 != 0);
  }
  const Bvh bvh(tris, casts, 2);
  std::vector<Ray> rays;
  for (int p = 0; p < 3000; ++p) {
    // A packet: a common origin or a common target, directions spread by `spread` (coherent to random).
    const glm::vec3 o{u(rng) * 12, u(rng) * 12, u(rng) * 12}, d{u(rng), u(rng), u(rng)};
    const float spread = p % 3 == 0 ? 0.01f : p % 3 == 1 ? 0.2f : 2.0f;
    for (int k = 0; k < 8; ++k) {
      Ray r{o, d + spread * glm::vec3{u(rng), u(rng), u(rng)}};
      if (p % 4 == 1) {
        r.origin = o + 3.0f * glm::vec3{u(rng), u(rng), u(rng)};
        r.direction = o - r.origin;
        r.tMax = 1.0f;
      }
      if (p % 13 == 2 && k == 3) r.direction = glm::vec3(0.0f);
      if (p % 17 == 3 && k == 5) r.tMax = 0.0f;
      if (p % 19 == 4 && k == 1) r.direction.y = 0.0f;
      if (p % 7 == 5) r.tMax = 3.0f;
      rays.push_back(r);
    }
  }
  const size_t hits = expectPacketsMatchSingles(bvh, rays);
  EXPECT_GT(hits, rays.size() / 5);
  EXPECT_LT(hits, rays.size() * 4 / 5);
  // Every packet width from 1 to 8 (the last packet of a row is short).
  for (int w = 1; w <= 8; ++w) expectPacketsMatchSingles(bvh, std::vector<Ray>(rays.begin(), rays.begin() + 400), w);
}

// A closed sphere seen from inside, near the origin and far from it (large coordinates, small radius):
// no ray may miss, in coherent packets (a common origin, neighbouring directions, as a camera's) and in
// packets aimed at every vertex and through the middle of every edge.
TEST(Packets, ClosedSphereFromInsideNeverMisses) {
  for (const auto& [centre, radius] :
       {std::pair{glm::vec3(0.1f, -0.2f, 0.3f), 1.3f}, std::pair{glm::vec3(3000.0f, -2000.0f, 1000.0f), 0.75f},
        std::pair{glm::vec3(1e-4f, 2e-4f, -1e-4f), 3e-4f}}) {
    const Mesh sphere = uvSphere(centre, radius, 16, 16);
    const std::vector<Triangle> tris = trianglesOf(sphere);
    const Bvh bvh(tris, {}, 1);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<Ray> rays;
    for (int p = 0; p < 1500; ++p) {
      const glm::vec3 o = centre + 0.5f * radius * glm::vec3{u(rng), u(rng), u(rng)};
      const glm::vec3 d{u(rng), u(rng), u(rng)};
      for (int k = 0; k < 8; ++k) rays.push_back({o, d + 0.05f * glm::vec3{u(rng), u(rng), u(rng)}});
    }
    const glm::vec3 o = centre + 0.25f * radius * glm::vec3(0.3f, -0.2f, 0.1f);
    for (const glm::vec3& v : sphere.positions) rays.push_back({o, v - o});
    for (size_t i = 0; i < sphere.indices.size(); i += 3)
      for (int e = 0; e < 3; ++e)
        rays.push_back(
            {o, 0.5f * (sphere.positions[sphere.indices[i + e]] + sphere.positions[sphere.indices[i + (e + 1) % 3]]) - o});
    EXPECT_EQ(expectPacketsMatchSingles(bvh, rays), rays.size()) << centre.x;
  }
}

// Rays through the shared diagonal of split quads and through shared vertices, in packets along the
// diagonal; and coplanar copies of one quad (exact ties of t, which the traversal order decides for a
// single ray: the packet must give the same triangle; here both orders happen to agree, so the retry of
// near-ties is guarded by RaysParallelToAxesAndFaces, whose rays through vertices fail without it).
TEST(Packets, SharedEdgesVerticesAndExactTies) {
  std::vector<Triangle> tris;
  for (int i = 0; i < 40; ++i) {
    const Mesh q = quad({float(i) * 3.0f, 0.0f, 0.0f}, {2.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f});
    for (const Triangle& t : trianglesOf(q)) tris.push_back(t);
  }
  for (int copy = 0; copy < 3; ++copy)  // three coplanar copies of a quad at z = -5
    for (const Triangle& t : trianglesOf(quad({0.0f, 0.0f, -5.0f}, {130.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f}))) tris.push_back(t);
  const Bvh bvh(tris, {}, 1);
  std::vector<Ray> rays;
  for (int i = 0; i < 40; ++i)
    for (int k = 0; k < 8; ++k) {
      const float s = float(k) / 7.0f;  // along the diagonal, both ends (shared vertices) included
      const glm::vec3 target{float(i) * 3.0f + 2.0f * s, 2.0f * s, 0.0f};
      rays.push_back({{float(i) * 3.0f + 1.0f, 1.0f, 4.0f}, target - glm::vec3(float(i) * 3.0f + 1.0f, 1.0f, 4.0f)});
    }
  // Through the gaps between the quads, onto the coplanar copies below.
  for (int i = 0; i < 39; ++i)
    for (int k = 0; k < 8; ++k)
      rays.push_back({{float(i) * 3.0f + 2.5f, 0.25f * float(k) / 7.0f + 0.5f, 4.0f}, {0.0001f * float(k), 0.0f, -1.0f}});
  // All but the rays at the quads' outer corners (an open mesh's corner may belong to neither triangle).
  EXPECT_GE(expectPacketsMatchSingles(bvh, rays), rays.size() - 80);
}

// Orthographic packets (rays parallel to two axes) through every vertex of a closed sphere, origins
// exactly on box planes, and rays parallel to the faces of a box.
TEST(Packets, RaysParallelToAxesAndFaces) {
  const Mesh sphere = uvSphere({0.25f, -0.5f, 0.125f}, 1.5f, 16, 16);
  std::vector<Triangle> tris = trianglesOf(sphere);
  for (const Triangle& t : trianglesOf(box({3.0f, 3.0f, 3.0f}, {4.0f, 4.0f, 4.0f}))) tris.push_back(t);
  const Bvh bvh(tris, {}, 1);
  std::vector<Ray> rays;
  for (int axis = 0; axis < 3; ++axis)
    for (const glm::vec3& v : sphere.positions) {
      Ray r;
      r.direction = glm::vec3(0.0f);
      r.direction[axis] = -1.0f;
      r.origin = v;
      r.origin[axis] = 10.0f;
      rays.push_back(r);
    }
  // Along the box's faces and edges (in their planes) and just above them.
  for (int k = 0; k < 64; ++k) {
    const float y = 3.0f + float(k % 8) / 7.0f, z = k < 32 ? 4.0f : 4.0f + float(k % 8) * 1e-7f;
    rays.push_back({{-1.0f, y, z}, {1.0f, 0.0f, 0.0f}});
    rays.push_back({{-1.0f, y, 3.0f + float(k % 8) / 7.0f}, {1.0f, 0.0f, 0.0f}});
  }
  EXPECT_GT(expectPacketsMatchSingles(bvh, rays), rays.size() / 2);
}

// A camera's packets, 8 pixels of a row (the image's right border leaves a short one) and the image
// split across the silhouette of a sphere: the tracer's own use. Perspective and orthographic.
TEST(Packets, CameraPacketsIncludingImageBorders) {
  const Mesh sphere = uvSphere({0.0f, 0.0f, 0.0f}, 1.0f, 48, 96);
  const Bvh bvh(trianglesOf(sphere), {}, 2);
  for (bool ortho : {false, true}) {
    Lens lens;
    lens.orthographic = ortho;
    lens.orthoHalfHeight = 1.2f;
    const CameraPose pose = frameBounds(sphere.bounds, lens, 1.0f);
    const int w = 61, h = 37;  // not multiples of 8
    std::vector<Ray> rays;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; x += 8) {
        std::vector<Ray> row;
        for (int k = x; k < std::min(w, x + 8); ++k) {
          const CameraRay cr = cameraRay(pose, lens, float(w) / float(h), pixelToNdc(k + 0.5f, y + 0.5f, w, h));
          row.push_back({cr.origin, cr.direction});
        }
        while (row.size() < 8) row.push_back(row.back());  // the border packet's padding, as a duplicate
        rays.insert(rays.end(), row.begin(), row.end());
      }
    const size_t hits = expectPacketsMatchSingles(bvh, rays, 8, ortho ? "ortho" : "perspective");
    EXPECT_GT(hits, rays.size() / 8);
    EXPECT_LT(hits, rays.size());
  }
}

// The counting traversal (bench-trace's work per ray): the same results, and counts that add up.
TEST(Packets, CountersCountTheWorkAndChangeNoResult) {
  const Mesh sphere = uvSphere({0.0f, 0.0f, 0.0f}, 1.0f, 48, 96);
  const Bvh bvh(trianglesOf(sphere), {}, 1);
  const Ray hit{{0.01f, 0.02f, 5.0f}, {0.0f, 0.0f, -1.0f}}, miss{{0.0f, 5.0f, 5.0f}, {0.0f, 0.0f, -1.0f}};
  const Hit plain = bvh.closest(hit);
  Bvh::counters() = {};
  bvh.closest(hit);
  EXPECT_EQ(Bvh::counters().nodes, 0u) << "counted while counting is off";
  Bvh::setCounting(true);
  const Hit counted = bvh.closest(hit);
  const BvhCounters one = Bvh::counters();
  EXPECT_EQ(std::memcmp(&plain, &counted, sizeof plain), 0);
  EXPECT_GE(one.nodes, 2u);
  EXPECT_GE(one.leaves, 1u);
  EXPECT_GE(one.packs, one.leaves);
  EXPECT_GE(one.triangles, one.packs);
  EXPECT_LE(one.triangles, 8 * one.packs);
  Bvh::counters() = {};
  bvh.closest(miss);  // misses the root's children: one node visit, nothing else
  EXPECT_EQ(Bvh::counters().nodes, 1u);
  EXPECT_EQ(Bvh::counters().leaves, 0u);
  // Eight copies of one ray: every lane live everywhere, no ray ever alone.
  Bvh::counters() = {};
  Ray rays[8];
  Hit h[8];
  for (Ray& r : rays) r = hit;
  bvh.closest8(rays, 8, h);
  const BvhCounters p = Bvh::counters();
  Bvh::setCounting(false);
  Bvh::counters() = {};
  EXPECT_EQ(std::memcmp(&plain, &h[7], sizeof plain), 0);
  EXPECT_EQ(p.packets, 1u);
  EXPECT_GE(p.packetNodes, 2u);
  EXPECT_EQ(p.packetNodeRays, 8 * p.packetNodes);
  EXPECT_GE(p.packetLeaves, 1u);
  EXPECT_EQ(p.packetLeafRays, 8 * p.packetLeaves);
  EXPECT_EQ(p.lone, 0u);
  EXPECT_EQ(p.packetTriangles + p.triangles, 8 * one.triangles) << "each ray tests what it tests alone";
}

// Each kind of packet hands off at its own threshold: eight copies of one ray stay a packet to the end
// with a threshold of 0, and walk alone from the root with 8.
TEST(Packets, HandOffFollowsTheKindOfRays) {
  const Mesh sphere = uvSphere({0.0f, 0.0f, 0.0f}, 1.0f, 48, 96);
  const Bvh bvh(trianglesOf(sphere), {}, 1);
  Ray rays[8];
  for (Ray& r : rays) r = {{0.01f, 0.02f, 5.0f}, {0.0f, 0.0f, -1.0f}};
  for (int k = 0; k < 3; ++k) {
    int alone[3] = {0, 0, 0};
    alone[k] = 8;
    Bvh::setPacketAloneRays(alone[0], alone[1], alone[2]);
    Bvh::setCounting(true);
    uint64_t lone[3];
    Hit h[8];
    Bvh::counters() = {};
    bvh.closest8(rays, 8, h);
    lone[0] = Bvh::counters().lone;
    Bvh::counters() = {};
    bvh.closest8(rays, 8, h, IntersectMethod::Watertight, PacketKind::Scattered);
    lone[1] = Bvh::counters().lone;
    Bvh::counters() = {};
    EXPECT_EQ(bvh.occluded8(rays, 8), 0xFFu);
    lone[2] = Bvh::counters().lone;
    Bvh::setCounting(false);
    Bvh::counters() = {};
    for (int j = 0; j < 3; ++j) EXPECT_EQ(lone[j], j == k ? 8u : 0u) << "threshold 8 for kind " << k << ", kind " << j;
  }
  Bvh::setPacketAloneRays(Bvh::kPacketAloneRays[0], Bvh::kPacketAloneRays[1], Bvh::kPacketAloneRays[2]);
}

TEST(Packets, EmptyBvh) {
  const Bvh empty(std::vector<Triangle>{});
  Ray r[2];
  Hit h[2];
  empty.closest8(r, 2, h);
  EXPECT_FALSE(h[0].hit());
  EXPECT_EQ(empty.occluded8(r, 2), 0u);
}

}  // namespace
}  // namespace rtr::trace
