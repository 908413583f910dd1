// A mesh's GPU records built in fixed pieces on several threads (render/mesh_records.hpp) are, byte for
// byte, those that appendClusters, appendClusterLods, enclosingSphere and appendClusterTree make one after
// another (GpuScene's build before the pieces): records, level-of-detail records, tree nodes, the nodes
// at each depth, the leaves and the mesh's two spheres; for a mesh with a hierarchy, one without (with and
// without level-of-detail records), and one without clusters.
#include <cmath>
#include <cstring>
#include <span>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.hpp"
#include "render/cull.hpp"
#include "render/mesh_records.hpp"
#include "scene/cluster_lod.hpp"
#include "scene/clusters.hpp"

namespace rtr::render {
namespace {

// A wavy sphere of rings x segments quads (two triangles each).
Mesh wavySphere(uint32_t rings, uint32_t segments) {
  Mesh m;
  for (uint32_t i = 0; i <= rings; ++i)
    for (uint32_t j = 0; j < segments; ++j) {
      const float th = float(i) / float(rings) * 3.14159265f, ph = float(j) / float(segments) * 6.2831853f;
      const float r = 1.0f + 0.05f * std::sin(7 * th) * std::cos(5 * ph);
      m.positions.push_back(r * glm::vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)));
    }
  auto at = [&](uint32_t i, uint32_t j) { return i * segments + j % segments; };
  for (uint32_t i = 0; i < rings; ++i)
    for (uint32_t j = 0; j < segments; ++j) {
      m.indices.insert(m.indices.end(), {at(i, j), at(i, j + 1), at(i + 1, j)});
      m.indices.insert(m.indices.end(), {at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)});
    }
  for (const glm::vec3& p : m.positions) m.normals.push_back(glm::normalize(p)), m.bounds.extend(p);
  return m;
}

// GpuScene's build as it was: the records appended one after another, the spheres around them, a tree per level.
struct Reference {
  std::vector<shader::GpuCluster> clusters;
  std::vector<shader::GpuClusterLod> lods;
  std::vector<shader::GpuCullNode> nodes;
  std::vector<uint32_t> depths;
  uint32_t level0 = 0, levels = 0, leaves = 0;
  glm::vec4 sphere{0.0f}, lodSphere{0.0f};
};

Reference reference(const Mesh& m, uint32_t flags, bool lods) {
  Reference r;
  appendClusters(m, glm::mat4(1.0f), 0, flags, r.clusters);
  r.level0 = uint32_t(r.clusters.size());
  if (lods) {
    appendClusterLods(m, glm::mat4(1.0f), 0, flags, false, 0, r.clusters, r.lods);
    appendClusterLods(m, glm::mat4(1.0f), 0, flags, true, 0, r.clusters, r.lods);
  }
  std::vector<glm::vec4> spheres;
  for (const shader::GpuCluster& c : r.clusters) spheres.push_back(c.sphere);
  r.sphere = enclosingSphere(spheres);
  spheres.clear();
  for (const shader::GpuClusterLod& l : r.lods) {
    spheres.push_back(l.sphere);
    if (l.error.y < shader::LOD_ERROR_INFINITE) spheres.push_back(l.parentSphere);
  }
  r.lodSphere = r.lods.empty() ? r.sphere : enclosingSphere(spheres);
  std::vector<glm::uvec2> runs{{0, r.level0}};
  uint32_t at = 0;
  for (size_t k = 0, c = r.level0; k < m.lod.clusters.size() && r.clusters.size() > r.level0; ++k) {
    if (m.lod.clusters[k].level == 0) continue;
    if (runs.size() == 1 || m.lod.clusters[k].level != at) runs.push_back({uint32_t(c), 0});
    at = m.lod.clusters[k].level, ++runs.back().y, ++c;
  }
  r.levels = uint32_t(runs.size());
  r.nodes.resize(runs.size());
  for (size_t l = 0; l < runs.size(); ++l)
    r.leaves += appendClusterTree(r.clusters, r.lods, runs[l].x, runs[l].y, uint32_t(l), r.nodes, r.depths);
  return r;
}

template <class A, class B>
bool sameBytes(const A& a, const B& b) {
  const std::span<const typename B::value_type> want(b);
  return a.size() == want.size() && (want.empty() || std::memcmp(a.data(), want.data(), want.size_bytes()) == 0);
}

// Every field of the pieces' build against the reference, for pieces of 1, 8 and 64 leaves and 1 or 3 threads.
void expectSameRecords(const Mesh& m, uint32_t flags, bool lods) {
  const Reference want = reference(m, flags, lods);
  ASSERT_GT(want.clusters.size(), 3 * 128u) << "four pieces of 128 records at least";
  for (size_t piece : {size_t(16), size_t(128), size_t(1024)})
    for (unsigned threads : {1u, 3u}) {
      SCOPED_TRACE("pieces of " + std::to_string(piece) + " records, " + std::to_string(threads) + " threads");
      const MeshRecords got = buildMeshRecords(m, flags, lods, threads, piece);
      EXPECT_EQ(got.count, want.clusters.size());
      EXPECT_EQ(got.level0, want.level0);
      EXPECT_EQ(got.levels, want.levels);
      EXPECT_EQ(got.leaves, want.leaves);
      EXPECT_EQ(got.depths, want.depths);
      EXPECT_TRUE(sameBytes(got.clusters, want.clusters)) << "records";
      EXPECT_TRUE(sameBytes(got.lods, want.lods)) << "level-of-detail records";
      EXPECT_TRUE(sameBytes(got.nodes, want.nodes)) << "tree nodes";
      EXPECT_EQ(std::memcmp(&got.sphere, &want.sphere, sizeof(glm::vec4)), 0) << "sphere";
      EXPECT_EQ(std::memcmp(&got.lodSphere, &want.lodSphere, sizeof(glm::vec4)), 0) << "level-of-detail sphere";
    }
}

TEST(MeshRecords, PiecesOnThreadsEqualTheRecordsBuiltInOrder) {
  Mesh m = wavySphere(120, 240);  // 57 600 triangles: 629 clusters, 1 706 with the hierarchy (12 levels)
  buildClusters(m, true);
  m.lod = buildClusterLod(m);
  ASSERT_GE(m.lod.levels, 4u);
  expectSameRecords(m, 0, true);
  expectSameRecords(m, CLUSTER_DOUBLE_SIDED, true);  // no cones
  m.lod = {};
  expectSameRecords(m, 0, true);   // no hierarchy, level-of-detail records (another mesh has one)
  expectSameRecords(m, 0, false);  // none
  m.clusters.clear();              // runs of triangles, spheres around their boxes
  expectSameRecords(m, 0, true);
  expectSameRecords(m, 0, false);
}

TEST(MeshRecords, PiecesAreSubtreesAndAHierarchyListsLevelZeroFirst) {
  Mesh m = wavySphere(20, 40);
  buildClusters(m, true);
  EXPECT_THROW(buildMeshRecords(m, 0, true, 1, 100), Error);  // not 16 times a power of 8
  m.lod = buildClusterLod(m);
  std::vector<LodCluster> lod(m.lod.clusters.begin(), m.lod.clusters.end());
  std::swap(lod.front(), lod.back());  // a level above first
  m.lod.clusters = std::move(lod);
  EXPECT_THROW(buildMeshRecords(m, 0, true, 1, 16), Error);
}

}  // namespace
}  // namespace rtr::render
