#include "scene/rtrscene_lod.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "cluster.h"
#include "cluster_lod.h"

namespace rtr {
namespace {

constexpr size_t kClusterSize = 96, kMeshSize = 16, kMaxLevels = 64;

template <class T>
T load(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

void vec4(ByteWriter& w, glm::vec4 v) {
  for (int k = 0; k < 4; ++k) w.f32(v[k]);
}

}  // namespace

bool hasClusterLods(const Scene& scene) {
  for (const Mesh& m : scene.meshes)
    if (m.lod.levels > 0) return true;
  return false;
}

void writeClusterLods(ByteWriter& w, const Scene& scene) {
  uint32_t meshes = 0;
  for (const Mesh& m : scene.meshes) meshes += m.lod.levels > 0;
  w.u32(meshes);
  w.zeros(12);
  for (uint32_t i = 0; i < scene.meshes.size(); ++i) {
    const ClusterLod& lod = scene.meshes[i].lod;
    if (lod.levels == 0) continue;
    for (uint32_t v : {i, lod.levels, uint32_t(lod.clusters.size()), uint32_t(lod.indices.size())}) w.u32(v);
    for (const LodCluster& c : lod.clusters) {  // 96 bytes each
      for (uint32_t v : {c.firstTriangle, c.triangleCount, c.level}) w.u32(v);
      w.f32(c.error);
      vec4(w, glm::vec4(c.center, c.radius));
      vec4(w, glm::vec4(c.coneAxis, c.coneCutoff));
      vec4(w, c.sphere);
      vec4(w, c.parentSphere);
      w.f32(c.parentError);
      w.zeros(12);
    }
    w.array(lod.indices);
    w.pad(16);
  }
}

void readClusterLodLayout(ByteReader& r, uint64_t size, Scene& scene, std::vector<LodLayout>& layout) {
  const size_t end = r.pos() + size;
  auto left = [&] { return end - r.pos(); };
  if (size < 16) r.fail("CLOD chunk: " + std::to_string(size) + " bytes, shorter than its 16-byte header");
  const size_t countAt = r.pos();
  const uint32_t meshes = r.u32("the CLOD chunk");
  for (int k = 0; k < 3; ++k)
    if (r.u32("the CLOD chunk") != 0) r.failAt(countAt + 4, "CLOD chunk: reserved field is not 0");
  if (uint64_t(meshes) * kMeshSize > left())
    r.failAt(countAt, "CLOD chunk: mesh count " + std::to_string(meshes) + " cannot fit in it");
  int64_t last = -1;
  for (uint32_t n = 0; n < meshes; ++n) {
    const size_t at = r.pos();
    if (left() < kMeshSize) r.fail("CLOD chunk: ends inside a mesh record");
    const uint32_t mi = r.u32("a CLOD mesh"), levels = r.u32("a CLOD mesh"), count = r.u32("a CLOD mesh"),
                   indexCount = r.u32("a CLOD mesh");
    if (int64_t(mi) <= last || mi >= scene.meshes.size())
      r.failAt(at, "CLOD chunk: mesh " + std::to_string(mi) + " out of range or not after mesh " + std::to_string(last) + " (" +
                       std::to_string(scene.meshes.size()) + " meshes)");
    last = mi;
    Mesh& m = scene.meshes[mi];
    const std::string which = "CLOD chunk: mesh " + std::to_string(mi) + ": ";
    const size_t base = m.clusters.size();
    if (levels < 1 || levels > kMaxLevels) r.failAt(at + 4, which + "level count " + std::to_string(levels) + " not in 1..64");
    if (base == 0 || count < base)
      r.failAt(at + 8, which + std::to_string(count) + " clusters, fewer than its " + std::to_string(base) + " own");
    if (indexCount % 3 != 0) r.failAt(at + 12, which + "index count " + std::to_string(indexCount) + " is not a multiple of 3");
    if ((uint64_t(count) * kClusterSize + uint64_t(indexCount) * 4) > left())
      r.failAt(at + 8, which + std::to_string(count) + " clusters and " + std::to_string(indexCount) +
                           " indices cannot fit in the chunk");
    LodLayout l{mi, count, indexCount, at};
    l.clustersAt = r.skipArray(count, kClusterSize, "CLOD clusters");
    l.indicesAt = r.skipArray(indexCount, 4, "CLOD indices");
    r.align(16, "CLOD indices");
    m.lod.levels = levels;

    layout.push_back(l);
  }
  if (r.pos() != end) r.fail("CLOD chunk: " + std::to_string(end - r.pos()) + " bytes after its last mesh");
}

void readLodClusters(const Mesh& m, LodCluster* out, const LodLayout& l, const uint8_t* file, size_t ownClustersAt,
                     uint32_t triangles, size_t first, size_t end) {
  const size_t base = m.clusters.size();
  const uint64_t all = uint64_t(triangles) + l.indexCount / 3;
  const std::string which = "CLOD chunk: mesh " + std::to_string(l.mesh) + ": ";
  auto fault = [&](size_t at, size_t k, const std::string& what) {
    throw ReadFault{at, which + "cluster " + std::to_string(k) + ": " + what};
  };
  auto u32 = [&](size_t k, size_t o) { return load<uint32_t>(file + l.clustersAt + k * kClusterSize + o); };
  for (size_t k = first; k < end; ++k) {
    const size_t cAt = l.clustersAt + k * kClusterSize;
    const uint8_t* q = file + cAt;
    // A record's checks in a fixed order (its first fault is thrown); of several records, rtrscene.cpp
    // reports the lowest fault.
    LodCluster c;
    c.firstTriangle = u32(k, 0);
    c.triangleCount = u32(k, 4);
    c.level = u32(k, 8);
    c.error = load<float>(q + 12);
    if (k < base) {  // level 0: the mesh's own clusters (their records in the file: 40 bytes, triangles at 32)
      const uint8_t* own = file + ownClustersAt + k * 40;
      if (c.level != 0 || c.firstTriangle != load<uint32_t>(own + 32) || c.triangleCount != load<uint32_t>(own + 36) ||
          c.error != 0.0f)
        fault(cAt, k, "level 0 must be the mesh's cluster " + std::to_string(k) + " with error 0");
    } else {  // above: levels in order, triangles tiling the hierarchy's after the mesh's own
      const uint64_t next = k == base ? triangles : uint64_t(u32(k - 1, 0)) + u32(k - 1, 4);
      if (c.firstTriangle != next)
        fault(cAt, k,
              "first triangle " + std::to_string(c.firstTriangle) + " is not " + std::to_string(next) +
                  " (clusters tile the hierarchy's triangles in order)");
      if (c.triangleCount < 1 || c.triangleCount > CLUSTER_MAX_TRIANGLES || next + c.triangleCount > all)
        fault(cAt + 4, k,
              "triangle count " + std::to_string(c.triangleCount) + " not in 1.." + std::to_string(CLUSTER_MAX_TRIANGLES) +
                  " or past the hierarchy's triangles");
      const uint32_t prev = u32(k - 1, 8);
      if (c.level < std::max(prev, 1u) || c.level >= m.lod.levels)
        fault(cAt + 8, k,
              "level " + std::to_string(c.level) + " not in " + std::to_string(std::max(prev, 1u)) + ".." +
                  std::to_string(m.lod.levels - 1));
    }
    for (size_t o = 12; o < 84; o += 4)
      if (!std::isfinite(load<float>(q + o)))
        throw ReadFault{cAt + o, std::string("CLOD chunk: ") +
                                     (o == 12  ? "a cluster's error"
                                      : o < 32 ? "a cluster's sphere"
                                      : o < 48 ? "a cluster's cone"
                                      : o < 64 ? "a cluster's error sphere"
                                      : o < 80 ? "a cluster's parent sphere"
                                               : "a cluster's parent error") +
                                     " is not finite"};
    const glm::vec4 bounds = load<glm::vec4>(q + 16), cone = load<glm::vec4>(q + 32);
    c.center = glm::vec3(bounds);
    c.radius = bounds.w;
    c.coneAxis = glm::vec3(cone);
    c.coneCutoff = cone.w;
    c.sphere = load<glm::vec4>(q + 48);
    c.parentSphere = load<glm::vec4>(q + 64);
    c.parentError = load<float>(q + 80);
    if (!(c.radius >= 0.0f && c.sphere.w >= 0.0f && c.parentSphere.w >= 0.0f && c.error >= 0.0f))
      fault(cAt + 12, k, "negative radius or error");
    if (c.coneCutoff < 1.0f && (c.coneCutoff < 0.0f || std::abs(glm::length(c.coneAxis) - 1.0f) > 1e-3f))
      fault(cAt + 32, k, "cone axis not a unit vector or cutoff below 0");
    if (!(c.parentError > c.error) || c.parentError > shader::LOD_ERROR_INFINITE)
      fault(cAt + 80, k, "parent error not above its own error");
    if (u32(k, 84) != 0 || u32(k, 88) != 0 || u32(k, 92) != 0) fault(cAt + 84, k, "reserved field is not 0");
    if (out) out[k] = c;
  }
  if (end == l.count) {  // the clusters above level 0 hold the hierarchy's triangles
    const uint64_t held = l.count > base ? uint64_t(u32(l.count - 1, 0)) + u32(l.count - 1, 4) - triangles : 0;
    if (held != l.indexCount / 3)
      throw ReadFault{l.at + 12,
                      which + std::to_string(l.indexCount / 3) + " triangles, but its clusters hold " + std::to_string(held)};
  }
}

void checkLodIndices(const LodLayout& l, const uint8_t* file, size_t vertices, size_t first, size_t end) {
  for (size_t k = first; k < end; ++k)
    if (const uint32_t v = load<uint32_t>(file + l.indicesAt + 4 * k); v >= vertices)
      throw ReadFault{l.indicesAt + 4 * k, "CLOD chunk: mesh " + std::to_string(l.mesh) + ": index " + std::to_string(v) +
                                               " out of range (" + std::to_string(vertices) + " vertices)"};
}

}  // namespace rtr
