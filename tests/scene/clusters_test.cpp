// Clusters: built with meshoptimizer, they tile the mesh's triangles (all kept, winding unchanged), stay
// within the GPU's limits, bound their triangles, and their cones only cull clusters that face away;
// .rtrscene version 3 stores them and refuses damaged ones.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "cluster.h"
#include "core/error.hpp"
#include "scene/binio.hpp"
#include "scene/clusters.hpp"
#include "scene/rtrscene.hpp"

using namespace rtr;
using ::testing::HasSubstr;

namespace {

// A bumpy height field of n×n quads (so cones differ), plus a degenerate and a repeated triangle.
Mesh bumpyGrid(uint32_t n) {
  Mesh m;
  m.name = "grid";
  for (uint32_t y = 0; y <= n; ++y)
    for (uint32_t x = 0; x <= n; ++x) {
      const float fx = float(x) / float(n), fy = float(y) / float(n);
      m.positions.push_back({fx * 4.0f, 0.3f * std::sin(fx * 17.0f) * std::cos(fy * 11.0f), fy * 4.0f});
    }
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      const uint32_t a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
      m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
    }
  m.indices.insert(m.indices.end(), {5, 5, 6, 0, n + 1, 1});
  m.normals.assign(m.positions.size(), glm::vec3(0, 1, 0));
  for (auto& p : m.positions) m.bounds.extend(p);
  return m;
}

// Each triangle rotated so its smallest index comes first: the same triangle with the same winding
// compares equal, a flipped one does not.
std::vector<std::array<uint32_t, 3>> canonicalTriangles(std::span<const uint32_t> idx) {
  std::vector<std::array<uint32_t, 3>> out;
  for (size_t i = 0; i < idx.size(); i += 3) {
    std::array<uint32_t, 3> t{idx[i], idx[i + 1], idx[i + 2]};
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    out.push_back(t);
  }
  std::sort(out.begin(), out.end());
  return out;
}

void expectValidClusters(const Mesh& m) {
  uint32_t next = 0;
  for (const Cluster& c : m.clusters) {
    EXPECT_EQ(c.firstTriangle, next);
    EXPECT_GE(c.triangleCount, 1u);
    EXPECT_LE(c.triangleCount, uint32_t(CLUSTER_MAX_TRIANGLES));
    std::vector<uint32_t> verts(m.indices.begin() + c.firstTriangle * 3,
                                m.indices.begin() + (c.firstTriangle + c.triangleCount) * 3);
    std::sort(verts.begin(), verts.end());
    EXPECT_LE(std::unique(verts.begin(), verts.end()) - verts.begin(), CLUSTER_MAX_VERTICES);
    // The sphere bounds what can be drawn: degenerate triangles (no area, no pixels) may lie outside it.
    for (uint32_t t = c.firstTriangle; t < c.firstTriangle + c.triangleCount; ++t) {
      const uint32_t* i = &m.indices[size_t(t) * 3];
      if (i[0] == i[1] || i[1] == i[2] || i[0] == i[2]) continue;
      for (int k = 0; k < 3; ++k) EXPECT_LE(glm::length(m.positions[i[k]] - c.center), c.radius * 1.0001f);
    }
    next += c.triangleCount;
  }
  EXPECT_EQ(next, m.triangleCount());
}

// The cone test of shaders/shared/cluster.h.
bool coneCulls(const Cluster& c, glm::vec3 eye) {
  const glm::vec3 d = c.center - eye;
  return c.coneCutoff < 1.0f && glm::dot(d, c.coneAxis) >= c.coneCutoff * glm::length(d) + c.radius;
}

}  // namespace

TEST(Clusters, KeepEveryTriangleAndItsWinding) {
  Mesh m = bumpyGrid(40);
  const auto before = canonicalTriangles(m.indices);
  buildClusters(m, true);
  EXPECT_EQ(canonicalTriangles(m.indices), before);
  EXPECT_GT(m.clusters.size(), size_t(3200 / CLUSTER_MAX_TRIANGLES));
  expectValidClusters(m);
}

// A mesh over 65 536 triangles is clustered in pieces on all cores: still every triangle once with its
// winding, clusters contiguous and within the limits, about as many as one piece would make, and the
// scene's meshes get the same clusters as one by one.
TEST(Clusters, BigMeshesAreClusteredInPiecesKeepingEveryTriangle) {
  Mesh m = bumpyGrid(200);  // 80 002 triangles: two pieces
  const auto before = canonicalTriangles(m.indices);
  Scene s;
  s.materials.resize(1);
  s.meshes = {m, bumpyGrid(190)};
  Scene oneThread = s;
  buildClusters(m, true);
  EXPECT_EQ(canonicalTriangles(m.indices), before);
  expectValidClusters(m);
  Mesh one = bumpyGrid(180);  // 64 802 triangles: one piece
  buildClusters(one, true);
  const double perTriangle = double(one.clusters.size()) / one.triangleCount();
  EXPECT_LE(double(m.clusters.size()) / m.triangleCount(), perTriangle * 1.02) << "pieces cost full clusters";
  EXPECT_EQ(buildMissingClusters(s), 2u);
  EXPECT_EQ(s.meshes[0].indices, m.indices);
  ASSERT_EQ(s.meshes[0].clusters.size(), m.clusters.size());
  for (size_t i = 0; i < m.clusters.size(); ++i)
    EXPECT_EQ(std::memcmp(&s.meshes[0].clusters[i], &m.clusters[i], sizeof(Cluster)), 0);
  expectValidClusters(s.meshes[1]);
  EXPECT_EQ(buildMissingClusters(oneThread, 1), 2u);  // rtr-bake --threads 1: the same pieces, the same clusters
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(oneThread.meshes[k].indices, s.meshes[k].indices);
    ASSERT_EQ(oneThread.meshes[k].clusters.size(), s.meshes[k].clusters.size());
    for (size_t i = 0; i < s.meshes[k].clusters.size(); ++i)
      EXPECT_EQ(std::memcmp(&oneThread.meshes[k].clusters[i], &s.meshes[k].clusters[i], sizeof(Cluster)), 0);
  }
}

// Each piece is clustered over its own vertices only: a mesh whose vertices are numbered with gaps (the
// same order, unused vertices far away between them) gets the same clusters, its indices in the gapped
// numbering, whether a piece's vertices lie close together or are spread over the whole mesh.
TEST(Clusters, PiecesSeeOnlyTheirOwnVertices) {
  Mesh plain = bumpyGrid(200);  // two pieces; the second one's vertices start far from 0
  plain.indices.resize(plain.indices.size() - 6);
  for (uint32_t gap : {2u, 100u}) {
    SCOPED_TRACE("gap " + std::to_string(gap));
    Mesh gapped = plain;
    gapped.positions.assign(plain.positions.size() * gap, glm::vec3(1e6f, -1e6f, 1e6f));
    for (size_t v = 0; v < plain.positions.size(); ++v) gapped.positions.writable()[v * gap] = plain.positions[v];
    gapped.normals.assign(gapped.positions.size(), glm::vec3(0, 1, 0));
    for (uint32_t& i : gapped.indices.writable()) i *= gap;
    Mesh a = plain;
    buildClusters(a, true);
    buildClusters(gapped, true);
    ASSERT_EQ(canonicalTriangles(a.indices), canonicalTriangles(plain.indices));
    ASSERT_EQ(gapped.indices.size(), a.indices.size());
    for (size_t k = 0; k < a.indices.size(); ++k) ASSERT_EQ(gapped.indices[k], a.indices[k] * gap) << k;
    ASSERT_EQ(gapped.clusters.size(), a.clusters.size());
    for (size_t i = 0; i < a.clusters.size(); ++i)
      EXPECT_EQ(std::memcmp(&gapped.clusters[i], &a.clusters[i], sizeof(Cluster)), 0) << "cluster " << i;
  }
}

// The input is checked in pieces on all cores, each mesh's positions before its indices: whatever the thread
// count, the error is the one a single pass in that order meets first.
TEST(Clusters, BadInputIsReportedAsOnePassWouldMeetIt) {
  Scene good;
  good.materials.resize(1);
  good.meshes = {bumpyGrid(450), bumpyGrid(20)};  // 203 401 positions, 1.2 M indices: several pieces of each
  good.meshes[1].name = "second";
  auto errorOf = [](Scene s, unsigned threads) -> std::string {
    try {
      buildMissingClusters(s, threads);
    } catch (const Error& e) { return e.what(); }
    return "(no error)";
  };
  const float nan = std::numeric_limits<float>::quiet_NaN();
  struct Case {
    std::function<void(Scene&)> damage;
    std::string error;
  };
  const std::vector<Case> cases = {
      {[&](Scene& s) {
         s.meshes[0].positions.writable()[200000].x = nan, s.meshes[0].positions.writable()[150000].y = 2e12f,
         s.meshes[0].positions.writable()[150001].z = nan;
       },
       "mesh 'grid': position 150000 is not finite"},
      {[&](Scene& s) { s.meshes[0].indices.writable().back() = 1u << 30, s.meshes[1].positions.writable()[0].x = nan; },
       "mesh 'grid': index 1073741824 out of range"},
      {[&](Scene& s) { s.meshes[0].indices.writable()[1000000] = 1u << 30, s.meshes[0].positions.writable().back().x = nan; },
       "mesh 'grid': position 203400 is not finite"},
      {[&](Scene& s) { s.meshes[0].indices.writable()[1000000] = 1u << 29, s.meshes[0].indices.writable()[1100000] = 1u << 30; },
       "mesh 'grid': index 536870912 out of range"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    Scene bad = good;
    cases[i].damage(bad);
    for (unsigned threads : {1u, 2u, 8u})
      EXPECT_THAT(errorOf(bad, threads), HasSubstr(cases[i].error)) << "case " << i << ", " << threads << " threads";
  }
}

TEST(Clusters, ConesOnlyCullClustersFacingAway) {
  Mesh m = bumpyGrid(40);
  buildClusters(m, true);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-10.0f, 10.0f);
  size_t culled = 0;
  for (int i = 0; i < 300; ++i) {
    const glm::vec3 eye{u(rng) + 2.0f, u(rng), u(rng) + 2.0f};
    for (const Cluster& c : m.clusters) {
      if (!coneCulls(c, eye)) continue;
      ++culled;
      for (uint32_t t = c.firstTriangle; t < c.firstTriangle + c.triangleCount; ++t) {
        const glm::vec3 a = m.positions[m.indices[t * 3]], b = m.positions[m.indices[t * 3 + 1]],
                        d = m.positions[m.indices[t * 3 + 2]];
        // Counter-clockwise front faces: a culled triangle is seen from behind (or edge on).
        EXPECT_GE(glm::dot(glm::cross(b - a, d - a), a - eye), 0.0f) << "cluster culled with a front face";
      }
    }
  }
  EXPECT_GT(culled, 100u) << "the cones cull nothing: the test would prove nothing";
}

TEST(Clusters, TwoSidedMaterialsHaveNoCone) {
  Mesh m = bumpyGrid(20);
  buildClusters(m, false);
  for (const Cluster& c : m.clusters) EXPECT_GE(c.coneCutoff, 1.0f);
  Material leaf;
  leaf.flags = kMaterialDoubleSided;
  EXPECT_FALSE(conesCull(leaf));
  leaf.flags = kMaterialAlphaMasked;
  EXPECT_FALSE(conesCull(leaf));
  EXPECT_TRUE(conesCull(Material{}));
}

namespace {

Scene gridScene() {
  Scene s;
  s.materials.push_back(Material{});
  s.meshes.push_back(bumpyGrid(30));
  return s;
}

std::string decodeError(const std::string& bytes) {
  try {
    decodeRtrScene({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()}, "g.rtrscene");
  } catch (const Error& e) { return e.what(); }
  return "(no error)";
}

void reseal(std::string& b) {
  const uint64_t payload = b.size() - 80;
  std::memcpy(b.data() + 32, &payload, 8);
  const uint64_t sum = pieceChecksum64({reinterpret_cast<const uint8_t*>(b.data()) + 80, payload});
  std::memcpy(b.data() + 40, &sum, 8);
}

}  // namespace

TEST(Clusters, RtrSceneStoresThemAndOlderVersionsLoadWithout) {
  Scene s = gridScene();
  const std::string plain = encodeRtrScene(s);  // no clusters yet: a count of 0
  buildMissingClusters(s);
  const Mesh& want = s.meshes[0];
  const std::string bytes = encodeRtrScene(s);
  const Scene got = decodeRtrScene({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()}, "g.rtrscene");
  const Mesh& m = got.meshes[0];
  EXPECT_EQ(m.indices, want.indices);
  ASSERT_EQ(m.clusters.size(), want.clusters.size());
  for (size_t i = 0; i < m.clusters.size(); ++i) {
    EXPECT_EQ(m.clusters[i].firstTriangle, want.clusters[i].firstTriangle);
    EXPECT_EQ(m.clusters[i].triangleCount, want.clusters[i].triangleCount);
    EXPECT_EQ(m.clusters[i].center, want.clusters[i].center);
    EXPECT_EQ(m.clusters[i].radius, want.clusters[i].radius);
    EXPECT_EQ(m.clusters[i].coneAxis, want.clusters[i].coneAxis);
    EXPECT_EQ(m.clusters[i].coneCutoff, want.clusters[i].coneCutoff);
  }
  // Version 2 has no clusters: it loads with none (loadScene then builds them).
  const std::string v2 = encodeRtrScene(gridScene(), 2);
  EXPECT_EQ(v2.size() + 16, encodeRtrScene(gridScene(), 3).size()) << "version 3 adds a 16-byte cluster header per mesh";
  const Scene old = decodeRtrScene({reinterpret_cast<const uint8_t*>(v2.data()), v2.size()}, "g.rtrscene");
  EXPECT_TRUE(old.meshes[0].clusters.empty());
  EXPECT_EQ(old.meshes[0].indices, gridScene().meshes[0].indices);
}

// meshoptimizer leaves a cluster of zero-area triangles with a zero cone axis and cutoff 0, which the
// loaders refuse: such a cluster gets a cone that never culls (seen in the 100M-triangle temple's bake).
TEST(Clusters, ZeroAreaTrianglesGetAConeThatNeverCullsAndLoad) {
  Scene s;
  s.materials.push_back(Material{});
  Mesh m = bumpyGrid(4);
  for (size_t i = 0; i + 2 < m.indices.size(); i += 3) m.indices.writable()[i + 2] = m.indices[i + 1];  // every triangle a line
  s.meshes.push_back(m);
  buildMissingClusters(s);
  ASSERT_FALSE(s.meshes[0].clusters.empty());
  for (const Cluster& c : s.meshes[0].clusters) EXPECT_EQ(c.coneCutoff, 1.0f);
  const std::string bytes = encodeRtrScene(s);
  EXPECT_EQ(decodeError(bytes), "(no error)");
}

TEST(Clusters, RtrSceneRefusesDamagedClusters) {
  Scene s = gridScene();
  buildMissingClusters(s);
  const std::string good = encodeRtrScene(s);
  ASSERT_EQ(decodeError(good), "(no error)");
  // Cluster records (40 bytes: centre, radius, axis, cutoff, first, count) run to the end of the file,
  // after padding to 16.
  const size_t n = s.meshes[0].clusters.size();
  const size_t first = good.size() - ((n * 40 + 15) / 16 * 16);
  auto patched = [&](size_t record, size_t field, const void* value) {
    std::string b = good;
    std::memcpy(b.data() + first + record * 40 + field, value, 4);
    reseal(b);
    return decodeError(b);
  };
  const uint32_t tooMany = CLUSTER_MAX_TRIANGLES + 1, shifted = 1, zero = 0;
  const float nan = std::nanf(""), tiny = 1e-3f, negative = -1.0f;
  EXPECT_THAT(patched(0, 36, &tooMany), HasSubstr("g.rtrscene: byte " + std::to_string(first + 36) +
                                                  ": mesh 0: cluster 0: triangle count 125 not in 1..124"));
  EXPECT_THAT(patched(0, 36, &zero), HasSubstr("cluster 0: triangle count 0"));
  EXPECT_THAT(patched(1, 32, &shifted), HasSubstr("cluster 1: first triangle 1 is not"));
  EXPECT_THAT(patched(2, 0, &nan), HasSubstr("a cluster's sphere is not finite"));
  EXPECT_THAT(patched(2, 28, &nan), HasSubstr("a cluster's cone is not finite"));
  EXPECT_THAT(patched(3, 12, &tiny), HasSubstr("cluster 3: vertex"));
  EXPECT_THAT(patched(3, 12, &negative), HasSubstr("cluster 3: negative radius"));
  const float halfAxis = 0.5f;  // x of the axis only; cutoff set below 1 so the cone counts
  const float cullingCutoff = 0.5f;
  std::string cone = good;
  std::memcpy(cone.data() + first + 4 * 40 + 16, &halfAxis, 4);
  std::memcpy(cone.data() + first + 4 * 40 + 16 + 4, &zero, 4);
  std::memcpy(cone.data() + first + 4 * 40 + 16 + 8, &zero, 4);
  std::memcpy(cone.data() + first + 4 * 40 + 28, &cullingCutoff, 4);
  reseal(cone);
  EXPECT_THAT(decodeError(cone), HasSubstr("cluster 4: cone axis not a unit vector or cutoff below 0"));
  EXPECT_THAT(patched(4, 28, &negative), HasSubstr("cluster 4: cone axis not a unit vector or cutoff below 0"));
  // The last cluster shortened: the triangles are not all covered.
  const uint32_t shorter = s.meshes[0].clusters.back().triangleCount - 1;
  EXPECT_THAT(patched(n - 1, 36, &shorter), HasSubstr("clusters cover"));
  // A count that cannot fit.
  std::string b = good;
  const uint32_t huge = 0x10000000;
  std::memcpy(b.data() + first - 16, &huge, 4);
  reseal(b);
  EXPECT_THAT(decodeError(b), HasSubstr("cluster count 268435456 does not fit"));
}
