// A scene's kinds (render/gpu_scene.hpp): from the Scene before the upload, and from what the upload made.
// The two must agree field by field (render_test SceneKindsAreWhatTheUploadMakes): each rule here is
// GpuScene's (planGeometry, placeRecords, buildRecords, startTextures) restated over the Scene.
#include <algorithm>

#include "cluster.h"
#include "raster.h"
#include "render/cull.hpp"
#include "render/gpu_scene.hpp"
#include "scene/textures.hpp"

namespace rtr::render {
namespace {

// The compute rasteriser's hand-off and tile lists name a cluster record in the bits above a triangle's.
constexpr uint64_t kMaxClusterRecords = uint64_t(1) << (32 - RASTER_LOCAL_BITS);

// Records of mesh m's own clusters (made where it has none: one per CLUSTER_MAX_TRIANGLES).
uint64_t ownClusters(const Mesh& m) {
  return m.clusters.empty() ? (m.indices.size() / 3 + CLUSTER_MAX_TRIANGLES - 1) / CLUSTER_MAX_TRIANGLES : m.clusters.size();
}

}  // namespace

SceneKinds sceneKinds(const Scene& scene) {
  SceneKinds k;
  k.texcoords = std::any_of(scene.meshes.begin(), scene.meshes.end(),
                            [](const Mesh& m) { return !m.indices.empty() && !m.texcoords.empty(); });
  k.materialExtras = std::any_of(scene.materials.begin(), scene.materials.end(),
                                 [](const Material& m) {
                                   return (m.flags & (kMaterialGltf | kMaterialUnlit)) ||
                                          std::any_of(m.uv.begin(), m.uv.end(),
                                                      [](const UvTransform& u) { return !u.identity() || u.texCoord != 0; });
                                 }) ||
                     std::any_of(scene.meshes.begin(), scene.meshes.end(),
                                 [](const Mesh& m) { return !m.colors.empty() || !m.tangents.empty() || !m.texcoords1.empty(); });
  k.textures = uint32_t(sampledTextures(scene).size());
  k.identityInstances = std::all_of(scene.instances.begin(), scene.instances.end(),
                                    [](const Instance& in) { return in.transform == glm::mat4(1.0f); });
  const bool lods = std::any_of(scene.meshes.begin(), scene.meshes.end(), [](const Mesh& m) { return m.lod.levels > 0; });
  const std::vector<Instance> instances = gpuInstances(scene);  // meshes with triangles only
  k.instances = uint32_t(instances.size());
  uint64_t clustersAtMost = 0;  // a mesh's hierarchy's records above level 0, bounded by all of them
  for (const Instance& in : instances) {
    const Mesh& m = scene.meshes[in.mesh];
    const Material& mat = scene.materials.at(m.material);
    if (mat.blended()) {
      k.blended = true;
      continue;
    }
    const DrawKind kind = m.texcoords.empty()    ? DrawKind::Untextured
                          : clusterFlags(m, mat) ? DrawKind::AlphaMasked
                                                 : DrawKind::Opaque;
    k.draws[size_t(kind)] = true;
    k.triangles += m.indices.size() / 3;
    k.visIds += uint32_t((m.indices.size() + m.lod.indices.size()) / 3);
    clustersAtMost += ownClusters(m) + (lods ? m.lod.clusters.size() : 0);
  }
  k.clusterIdsFit = clustersAtMost < kMaxClusterRecords;
  if (!k.clusterIdsFit) {  // count them (reads every hierarchy record: only where the bound does not settle it)
    uint64_t clusters = 0;
    for (const Instance& in : instances) {
      const Mesh& m = scene.meshes[in.mesh];
      if (scene.materials.at(m.material).blended()) continue;
      clusters += ownClusters(m);
      if (lods)
        clusters += uint64_t(
            std::count_if(m.lod.clusters.begin(), m.lod.clusters.end(), [](const LodCluster& c) { return c.level > 0; }));
    }
    k.clusterIdsFit = std::min<uint64_t>(clusters, UINT32_MAX) < kMaxClusterRecords;
  }
  return k;
}

SceneKinds GpuScene::kinds() const {
  SceneKinds k;
  for (size_t d = 0; d < kDrawKindCount; ++d) {
    k.draws[d] = hasDraws(DrawKind(d));
    for (const DrawItem& item : draws_[d]) k.triangles += uint64_t(item.indexCount / 3) * item.instanceCount;
  }
  k.blended = !blendDraws_.empty();
  k.texcoords = texcoords() != VK_NULL_HANDLE;
  k.identityInstances = identityInstances_;
  k.materialExtras = materialExtras_;
  k.textures = textureCount();
  k.instances = instanceCount();
  k.visIds = visIdCount_;
  k.clusterIdsFit = clusterCount_ < kMaxClusterRecords;
  return k;
}

}  // namespace rtr::render
