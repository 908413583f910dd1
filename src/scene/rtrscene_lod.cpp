#include "scene/rtrscene_lod.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/parallel.hpp"

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

void readClusterLods(ByteReader& r, uint64_t size, Scene& scene) {
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
    ClusterLod& lod = m.lod;
    lod.levels = levels;
    lod.clusters.resize(count);
    const uint32_t triangles = m.triangleCount();
    auto cl = [&](size_t k) { return which + "cluster " + std::to_string(k) + ": "; };  // built only for an error
    // Each record read and checked on its own in pieces on all cores (a serial read of the fields was most of
    // the chunk's time at 10 M triangles); the checks that chain records (levels, triangle runs) follow.
    const size_t clustersAt = r.pos();
    const auto* bytes = reinterpret_cast<const uint8_t*>(r.view(size_t(count) * kClusterSize, "CLOD clusters").data());
    constexpr size_t kPiece = 4096;
    parallelFor((size_t(count) + kPiece - 1) / kPiece, 0, [&](size_t piece) {
      for (size_t k = piece * kPiece, e = std::min<size_t>(k + kPiece, count); k < e; ++k) {
        const size_t cAt = clustersAt + k * kClusterSize;
        const uint8_t* q = bytes + k * kClusterSize;
        auto u32 = [&](size_t o) { return load<uint32_t>(q + o); };
        auto f32 = [&](size_t o, const char* what) {
          const float f = load<float>(q + o);
          if (!std::isfinite(f)) r.failAt(cAt + o, std::string("CLOD chunk: ") + what + " is not finite");
          return f;
        };
        auto v4 = [&](size_t o, const char* what) {
          return glm::vec4(f32(o, what), f32(o + 4, what), f32(o + 8, what), f32(o + 12, what));
        };
        LodCluster& c = lod.clusters[k];
        c.firstTriangle = u32(0);
        c.triangleCount = u32(4);
        c.level = u32(8);
        c.error = f32(12, "a cluster's error");
        const glm::vec4 bounds = v4(16, "a cluster's sphere"), cone = v4(32, "a cluster's cone");
        c.center = glm::vec3(bounds);
        c.radius = bounds.w;
        c.coneAxis = glm::vec3(cone);
        c.coneCutoff = cone.w;
        c.sphere = v4(48, "a cluster's error sphere");
        c.parentSphere = v4(64, "a cluster's parent sphere");
        c.parentError = f32(80, "a cluster's parent error");
        if (u32(84) != 0 || u32(88) != 0 || u32(92) != 0) r.failAt(cAt + 84, cl(k) + "reserved field is not 0");
        if (k < base) {  // level 0: the mesh's own clusters
          const Cluster& own = m.clusters[k];
          if (c.level != 0 || c.firstTriangle != own.firstTriangle || c.triangleCount != own.triangleCount || c.error != 0.0f)
            r.failAt(cAt, cl(k) + "level 0 must be the mesh's cluster " + std::to_string(k) + " with error 0");
        }
        if (!(c.radius >= 0.0f && c.sphere.w >= 0.0f && c.parentSphere.w >= 0.0f && c.error >= 0.0f))
          r.failAt(cAt + 12, cl(k) + "negative radius or error");
        if (!(c.parentError > c.error) || c.parentError > shader::LOD_ERROR_INFINITE)
          r.failAt(cAt + 80, cl(k) + "parent error not above its own error");
        if (c.coneCutoff < 1.0f && (c.coneCutoff < 0.0f || std::abs(glm::length(c.coneAxis) - 1.0f) > 1e-3f))
          r.failAt(cAt + 32, cl(k) + "cone axis not a unit vector or cutoff below 0");
      }
    });
    uint64_t next = triangles;  // where the next cluster above level 0 starts
    for (size_t k = base; k < count; ++k) {
      const size_t cAt = clustersAt + k * kClusterSize;
      const LodCluster& c = lod.clusters[k];
      const uint32_t prev = lod.clusters[k - 1].level;
      if (c.level < std::max(prev, 1u) || c.level >= levels)
        r.failAt(cAt + 8, cl(k) + "level " + std::to_string(c.level) + " not in " + std::to_string(std::max(prev, 1u)) + ".." +
                              std::to_string(levels - 1));
      if (c.firstTriangle != next)
        r.failAt(cAt, cl(k) + "first triangle " + std::to_string(c.firstTriangle) + " is not " + std::to_string(next) +
                          " (clusters tile the hierarchy's triangles in order)");
      if (c.triangleCount < 1 || c.triangleCount > CLUSTER_MAX_TRIANGLES || next + c.triangleCount > triangles + indexCount / 3)
        r.failAt(cAt + 4, cl(k) + "triangle count " + std::to_string(c.triangleCount) + " not in 1.." +
                              std::to_string(CLUSTER_MAX_TRIANGLES) + " or past the hierarchy's triangles");
      next += c.triangleCount;
    }
    if (next != uint64_t(triangles) + indexCount / 3)
      r.failAt(at + 12,
               which + std::to_string(indexCount / 3) + " triangles, but its clusters hold " + std::to_string(next - triangles));
    const size_t iAt = r.pos();
    r.array(lod.indices, indexCount, "CLOD indices");
    // Checked in pieces on all cores (the hierarchy holds about as many indices as the mesh); the first
    // bad one is reported, as a serial check would.
    constexpr size_t kIndexPiece = size_t(1) << 20;
    std::vector<size_t> bad((lod.indices.size() + kIndexPiece - 1) / kIndexPiece, SIZE_MAX);
    parallelFor(bad.size(), 0, [&](size_t p) {
      for (size_t k = p * kIndexPiece, e = std::min(k + kIndexPiece, lod.indices.size()); k < e; ++k)
        if (lod.indices[k] >= m.positions.size()) {
          bad[p] = k;
          return;
        }
    });
    for (const size_t k : bad)
      if (k != SIZE_MAX)
        r.failAt(iAt + 4 * k, which + "index " + std::to_string(lod.indices[k]) + " out of range (" +
                                  std::to_string(m.positions.size()) + " vertices)");
    r.align(16, "CLOD indices");
  }
  if (r.pos() != end) r.fail("CLOD chunk: " + std::to_string(end - r.pos()) + " bytes after its last mesh");
}

}  // namespace rtr
