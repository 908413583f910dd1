// The BVH against brute force: same closest hits, any-hit agrees, shadow flags respected.
#include "trace/bvh.hpp"

#include <algorithm>
#include <cstring>
#include <random>

#include <glm/geometric.hpp>

#include "trace/procedural.hpp"

#include <gtest/gtest.h>

namespace rtr::trace {
namespace {

Hit bruteForce(const std::vector<Triangle>& tris, Ray r, IntersectMethod m) {
  Hit best;
  for (uint32_t i = 0; i < tris.size(); ++i) {
    float b1, b2;
    const float t = intersect(m, r, tris[i], b1, b2);
    if (t > 0.0f) {
      best = {t, b1, b2, i};
      r.tMax = t;
    }
  }
  return best;
}

TEST(Bvh, MatchesBruteForceOnATriangleSoup) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Triangle> tris;
  for (int i = 0; i < 3000; ++i) {
    const glm::vec3 c{u(rng) * 10, u(rng) * 10, u(rng) * 10};
    tris.push_back({c, c + glm::vec3{u(rng), u(rng), u(rng)}, c + glm::vec3{u(rng), u(rng), u(rng)}});
  }
  std::vector<uint8_t> casts(tris.size(), 1);
  const Bvh bvh(tris, casts, 2);
  EXPECT_GT(bvh.stats().nodes, 10u);
  EXPECT_EQ(bvh.stats().triangles, tris.size());
  // Every traversal ISA (those the CPU lacks run as the best one below), every routine.
  for (BvhIsa isa : {BvhIsa::Avx512, BvhIsa::Avx2, BvhIsa::Sse})
    for (IntersectMethod m : {IntersectMethod::Watertight, IntersectMethod::HalfPlane, IntersectMethod::MollerTrumbore}) {
      Bvh::setIsa(isa);
      int hits = 0;
      for (int i = 0; i < 3000; ++i) {
        Ray r{{u(rng) * 12, u(rng) * 12, u(rng) * 12}, {u(rng), u(rng), u(rng)}};
        if (i % 3 == 0) r.direction.y = 0.0f;  // axis-parallel components exercise the slab test's zero case
        if (i % 7 == 0) r.tMax = 5.0f;
        const Hit a = bvh.closest(r, m), b = bruteForce(tris, r, m);
        ASSERT_EQ(a.hit(), b.hit()) << i;
        ASSERT_EQ(bvh.occluded(r, m), b.hit()) << i;
        if (a.hit()) {
          ++hits;
          EXPECT_EQ(a.t, b.t) << i;
          EXPECT_EQ(a.prim, b.prim) << i;
          EXPECT_EQ(a.b1, b.b1) << i;
        }
      }
      EXPECT_GT(hits, 300);
    }
  Bvh::setIsa(BvhIsa::Avx512);
}

// Two rays walked together give each exactly what it gets alone: rays in general directions, rays
// parallel to the same axis (walked together too) or to different ones, a zero direction, short tMax,
// pairs where one ray ends long before the other (one misses the scene), and each routine and ISA.
TEST(Bvh, PairsGiveExactlyTheResultsOfSingleRays) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Triangle> tris;
  std::vector<uint8_t> casts;
  for (int i = 0; i < 4000; ++i) {
    const glm::vec3 c{u(rng) * 10, u(rng) * 10, u(rng) * 10};
    tris.push_back({c, c + glm::vec3{u(rng), u(rng), u(rng)}, c + glm::vec3{u(rng), u(rng), u(rng)}});
    casts.push_back(i % 5 != 0);
  }
  const Bvh bvh(tris, casts, 2);
  auto randomRay = [&](int i) {
    Ray r{{u(rng) * 12, u(rng) * 12, u(rng) * 12}, {u(rng), u(rng), u(rng)}};
    if (i % 5 == 1) r.direction.y = 0.0f;
    if (i % 5 == 2) r.direction.x = r.direction.z = 0.0f;
    if (i % 7 == 3) r.tMax = 4.0f;
    if (i % 11 == 4) r.origin = {40.0f, 40.0f, 40.0f};  // misses the root: ends at once
    if (i % 29 == 5) r.direction = glm::vec3(0.0f);
    return r;
  };
  for (BvhIsa isa : {BvhIsa::Avx512, BvhIsa::Avx2, BvhIsa::Sse})
    for (IntersectMethod m : {IntersectMethod::Watertight, IntersectMethod::HalfPlane, IntersectMethod::MollerTrumbore}) {
      Bvh::setIsa(isa);
      int hits = 0, occluded = 0;
      for (int i = 0; i < 4000; ++i) {
        const std::array<Ray, 2> rays{randomRay(i), randomRay(i / 2)};
        const std::array<Hit, 2> pair = bvh.closestPair(rays, m);
        const std::array<bool, 2> occ = bvh.occludedPair(rays, m);
        for (int k = 0; k < 2; ++k) {
          const Hit one = bvh.closest(rays[k], m);
          ASSERT_EQ(pair[k].prim, one.prim) << Bvh::isaName(isa) << " pair " << i << " ray " << k;
          EXPECT_EQ(pair[k].t, one.t) << i;
          EXPECT_EQ(pair[k].b1, one.b1) << i;
          EXPECT_EQ(pair[k].b2, one.b2) << i;
          ASSERT_EQ(occ[k], bvh.occluded(rays[k], m)) << Bvh::isaName(isa) << " pair " << i << " ray " << k;
          hits += one.hit();
          occluded += occ[k];
        }
      }
      EXPECT_GT(hits, 1000);
      EXPECT_GT(occluded, 1000);
      EXPECT_LT(occluded, hits);  // non-casters: some hits cast no shadow
    }
  Bvh::setIsa(BvhIsa::Avx512);
  const Bvh empty(std::vector<Triangle>{});
  EXPECT_FALSE(empty.closestPair({Ray{}, Ray{}})[1].hit());
  EXPECT_FALSE(empty.occludedPair({Ray{}, Ray{}})[0]);
}

// Orthographic views and axis-aligned rays: direction components exactly zero, and origins exactly on
// box planes (the rays pass through vertices, whose coordinates bound the boxes). The parallel axes are
// tested exactly (lo ≤ o ≤ hi); any box culled wrongly shows up as a difference from brute force, and
// the closed sphere must never let a ray through.
TEST(Bvh, AxisParallelRaysThroughVerticesMatchBruteForce) {
  const Mesh sphere = uvSphere({0.25f, -0.5f, 0.125f}, 1.5f, 16, 16);
  std::vector<Triangle> tris;
  for (size_t i = 0; i < sphere.indices.size(); i += 3)
    tris.push_back(
        {sphere.positions[sphere.indices[i]], sphere.positions[sphere.indices[i + 1]], sphere.positions[sphere.indices[i + 2]]});
  const Bvh bvh(tris, {}, 1);
  for (BvhIsa isa : {BvhIsa::Avx512, BvhIsa::Avx2, BvhIsa::Sse}) {
    Bvh::setIsa(isa);
    size_t rays = 0, hits = 0;
    for (const glm::vec3& v : sphere.positions)
      for (int axis = 0; axis < 3; ++axis)
        for (float sign : {1.0f, -1.0f}) {
          Ray r;
          r.direction = glm::vec3(0.0f);
          r.direction[axis] = -sign;
          r.origin = v;
          r.origin[axis] = sphere.bounds.center()[axis] + sign * 10.0f;  // outside, on the vertex's line
          const Hit a = bvh.closest(r), b = bruteForce(tris, r, IntersectMethod::Watertight);
          ASSERT_EQ(a.hit(), b.hit()) << Bvh::isaName(isa) << " vertex " << v.x << "," << v.y << "," << v.z;
          // Through a vertex, several triangles give the same t up to rounding: any of them may win.
          if (a.hit()) { ASSERT_NEAR(a.t, b.t, 1e-6f * b.t); }
          ASSERT_EQ(bvh.occluded(r), b.hit());
          ++rays;
          hits += a.hit();
          const glm::vec3 off = v - sphere.bounds.center();
          // A vertex well inside the silhouette along this axis: the closed sphere cannot miss.
          glm::vec3 across = off;
          across[axis] = 0.0f;
          if (glm::length(across) < 1.2f) { EXPECT_TRUE(a.hit()); }
        }
    // From the centre along each axis and each diagonal of two axes (one or two parallel axes).
    for (int mask = 1; mask < 7; ++mask)
      for (float sign : {1.0f, -1.0f}) {
        Ray r{sphere.bounds.center(), glm::vec3(float(mask & 1), float(mask >> 1 & 1), float(mask >> 2 & 1)) * sign};
        const Hit a = bvh.closest(r), b = bruteForce(tris, r, IntersectMethod::Watertight);
        EXPECT_TRUE(a.hit()) << mask;
        EXPECT_NEAR(a.t, b.t, 1e-6f * b.t) << mask;
      }
    EXPECT_EQ(rays, sphere.positions.size() * 6);
    EXPECT_GT(hits, rays / 2);
  }
  Bvh::setIsa(BvhIsa::Avx512);
}

TEST(Bvh, ShadowRaysIgnoreNonCasters) {
  const std::vector<Triangle> tris{{{-1, -1, -1}, {1, -1, -1}, {0, 1, -1}}, {{-1, -1, -2}, {1, -1, -2}, {0, 1, -2}}};
  const Ray r{{0, 0, 0}, {0, 0, -1}};
  EXPECT_TRUE(Bvh(tris, std::vector<uint8_t>{1, 1}).occluded(r));
  EXPECT_TRUE(Bvh(tris, std::vector<uint8_t>{0, 1}).occluded(r));
  EXPECT_FALSE(Bvh(tris, std::vector<uint8_t>{0, 0}).occluded(r));
  // Closest hit still sees non-casters (lights are visible).
  EXPECT_EQ(Bvh(tris, std::vector<uint8_t>{0, 0}).closest(r).prim, 0u);
}

TEST(Bvh, EmptyAndDegenerateInputs) {
  const Bvh empty(std::vector<Triangle>{});
  EXPECT_FALSE(empty.closest({{0, 0, 0}, {0, 0, -1}}).hit());
  // Many triangles with the same centroid: the build must still terminate and find them.
  std::vector<Triangle> same(100, Triangle{{-1, -1, -1}, {1, -1, -1}, {0, 1, -1}});
  const Bvh bvh(same);
  EXPECT_TRUE(bvh.closest({{0, 0, 0}, {0, 0, -1}}).hit());
  // Non-finite coordinates are left out rather than poisoning the boxes.
  std::vector<Triangle> bad{{{NAN, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{-1, -1, -1}, {1, -1, -1}, {0, 1, -1}}};
  EXPECT_EQ(Bvh(bad).closest({{0, 0, 0}, {0, 0, -1}}).prim, 1u);
}

// The parallel build (ranges near the root binned and partitioned by many threads, subtrees side by side)
// makes the very tree one thread makes: nodes and packs bit for bit. And that tree is sound: child
// boxes inside their parent's, each leaf's triangles inside its box, every triangle in exactly one leaf.
TEST(Bvh, ParallelBuildMakesTheSingleThreadTree) {
  const Mesh sphere = uvSphere({0.5f, -0.25f, 2.0f}, 3.0f, 300, 600);  // big enough for parallel binning
  std::vector<Triangle> tris;
  for (size_t i = 0; i < sphere.indices.size(); i += 3)
    tris.push_back(
        {sphere.positions[sphere.indices[i]], sphere.positions[sphere.indices[i + 1]], sphere.positions[sphere.indices[i + 2]]});
  tris.insert(tris.end(), 1000, Triangle{{-1, -1, -1}, {1, -1, -1}, {0, 1, -1}});  // one centroid: median splits
  // Non-finite triangles in the first chunks of the parallel reference pass: the chunks after them must
  // close up.
  std::vector<uint32_t> bad;
  for (uint32_t i = 5; i < tris.size(); i += 37'001) {
    tris[i].v1.y = i % 2 ? NAN : INFINITY;
    bad.push_back(i);
  }
  // 8 threads: the root's splits by all threads; 16: its children's too (a level of fewer nodes than threads).
  const Bvh one(tris, {}, 1), many(tris, {}, 8), more(tris, {}, 16);
  // A finer grain (bench-trace's sweep): more subtree tasks, and chunks of 1 K references on every level
  // with fewer nodes than threads.
  Bvh::setBuildGrain(256, 1024);
  const Bvh fine(tris, {}, 16);
  Bvh::setBuildGrain(Bvh::kSubtreeTask, Bvh::kParallelChunk);
  ASSERT_GT(tris.size(), 300000u);
  const Bvh::View a = one.view();
  for (const Bvh* other : {&many, &more, &fine}) {
    ASSERT_EQ(one.stats().nodes, other->stats().nodes);
    ASSERT_EQ(one.stats().packs, other->stats().packs);
    EXPECT_EQ(one.sahCost(), other->sahCost());
    const Bvh::View b = other->view();
    EXPECT_EQ(a.root, b.root);
    for (uint32_t i = 0; i < one.stats().nodes; ++i)  // field by field: a Node has padding
      ASSERT_TRUE(!std::memcmp(a.nodes[i].box, b.nodes[i].box, sizeof a.nodes[i].box) &&
                  !std::memcmp(a.nodes[i].child, b.nodes[i].child, sizeof a.nodes[i].child))
          << "node " << i;
    for (uint32_t i = 0; i < one.stats().packs; ++i)
      ASSERT_TRUE(!std::memcmp(a.packs[i].v, b.packs[i].v, sizeof a.packs[i].v) &&
                  !std::memcmp(a.packs[i].prim, b.packs[i].prim, sizeof a.packs[i].prim))
          << "pack " << i;
  }
  EXPECT_GT(one.sahCost(), 1.0);
  const Bvh::View b = many.view();

  std::vector<int> seen(tris.size(), 0);
  size_t leaves = 0;
  std::vector<uint32_t> stack{b.root};
  while (!stack.empty()) {
    const Node& n = b.nodes[stack.back()];
    stack.pop_back();
    for (int k = 0; k < 8; ++k) {
      if (!(n.box[0][0][k] <= n.box[1][0][k])) continue;  // empty slot
      const auto inside = [&](float x, int axis) { return n.box[0][axis][k] <= x && x <= n.box[1][axis][k]; };
      const uint32_t c = n.child[k];
      if (c & Bvh::kLeafBit) {
        ++leaves;
        const uint32_t first = c & 0x0FFFFFFFu, np = ((c >> 28) & 7u) + 1;
        for (uint32_t p = first; p < first + np; ++p)
          for (int lane = 0; lane < 8; ++lane) {
            const TriPack& pk = b.packs[p];
            for (int v = 0; v < 3; ++v)
              for (int axis = 0; axis < 3; ++axis) ASSERT_TRUE(inside(pk.v[v][axis][lane], axis));
            if (lane == 0 || pk.prim[lane] != pk.prim[lane - 1]) ++seen[pk.prim[lane]];  // a short pack repeats
          }
      } else {
        const Node& child = b.nodes[c];
        for (int j = 0; j < 8; ++j) {
          if (child.box[0][0][j] > child.box[1][0][j]) continue;  // an empty slot
          for (int axis = 0; axis < 3; ++axis)
            ASSERT_TRUE(inside(child.box[0][axis][j], axis) && inside(child.box[1][axis][j], axis));
        }
        stack.push_back(c);
      }
    }
  }
  EXPECT_GT(leaves, 1000u);
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), std::ptrdiff_t(tris.size() - bad.size()));
  for (uint32_t i : bad) EXPECT_EQ(seen[i], 0) << i;

  // And so the same answers: rays from inside the closed sphere all hit.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 2000; ++i) {
    const Ray r{{0.5f, -0.25f, 2.0f}, {u(rng), u(rng), u(rng)}};
    const Hit h1 = one.closest(r), h8 = many.closest(r);
    ASSERT_TRUE(h8.hit()) << i;
    EXPECT_EQ(h1.prim, h8.prim);
    EXPECT_EQ(h1.t, h8.t);
  }
}

}  // namespace
}  // namespace rtr::trace
