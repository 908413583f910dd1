#pragma once
// GPU-driven cluster culling (docs/culling.md). A compute pass tests every GpuCluster (cluster.h) against
// the frustum, its back-face cone and a hierarchical depth pyramid, and writes the indices of the visible
// ones compacted into one buffer plus an indirect dispatch argument of one workgroup per visible cluster;
// culled clusters are counted by reason. The tests themselves are shaders/shared/cull.h (shared with the
// CPU reference of the tests).
//
// Use, per frame (two-phase, CullPhase below): culler.record(Early); dispatch indirect on counts() over
// visible(); pyramid.build(depth of that); culler.record(Late, &pyramid); dispatch again. docs/culling.md.
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "core/enum_names.hpp"
#include "cull.h"
#include "core/bounds.hpp"
#include "scene/scene.hpp"
#include "vk/pipeline.hpp"
#include "vk/resources.hpp"

namespace rtr::vk {
class Context;
}

namespace rtr::render {

// The instances a scene draws, in the GPU's order (GpuScene's GpuInstance buffer, the high bits of a
// visibility id): Scene::instances, or each mesh once untransformed; those of meshes without triangles
// dropped; grouped by mesh, then mirrored ones after the others (stable), so that the instances one
// instanced draw covers are one range.
std::vector<Instance> gpuInstances(const Scene& scene);
// Whether a transform flips the winding (negative determinant).
bool mirrored(const glm::mat4& transform);
// The linear part's largest stretch (a column's length for a similarity, else the Frobenius norm, an
// upper bound), and whether it is a similarity (rotation, uniform scale, mirror).
std::pair<float, bool> largestStretch(const glm::mat4& transform);

// The CLUSTER_* flags of a mesh's clusters: the GPU's alpha-tested, two-sided draws are double-sided,
// and alpha-masked where they have a mask texture (render/gpu_scene.cpp's draw kinds).
uint32_t clusterFlags(const Mesh& mesh, const Material& material);
// Appends the scene-space records of `mesh`'s clusters placed by `transform` (instance `instance`): the
// mesh's own (meshoptimizer, scene/clusters.hpp) or, for a mesh built without them, runs of up to
// CLUSTER_MAX_TRIANGLES triangles with a sphere around their box and no cone. The sphere's centre is
// transformed and its radius scaled by the largest stretch; the cone's axis is rotated with it where the
// transform is a similarity (rotation, uniform scale, mirror), else dropped (a non-uniform scale bends
// the normals' cone). Double-sided clusters get no cone. Identity: the records as stored, bit for bit.
void appendClusters(const Mesh& mesh, const glm::mat4& transform, uint32_t instance, uint32_t flags,
                    std::vector<shader::GpuCluster>& out);
// The level-of-detail records (docs/virtual-geometry.md) of the clusters appendClusters appended from
// `first` on (a mesh without a hierarchy: always in the cut), or, with `above`, the records of its
// hierarchy's clusters above level 0 appended to `out` and their level-of-detail records to `lods`; all
// placed by `transform` as appendClusters places them, errors scaled by its largest stretch.
void appendClusterLods(const Mesh& mesh, const glm::mat4& transform, uint32_t instance, uint32_t flags, bool above, size_t first,
                       std::vector<shader::GpuCluster>& out, std::vector<shader::GpuClusterLod>& lods);
// One record of each kind in the mesh's space, as the two above make them (and render/mesh_records.cpp):
// a mesh's or a hierarchy's cluster (C: Cluster or LodCluster; a double-sided one has no cone); the run of
// up to CLUSTER_MAX_TRIANGLES triangles from `first` of a mesh without clusters (a sphere around its box, no
// cone); a hierarchy cluster's level-of-detail record; and that of a record always in the cut (no hierarchy).
template <class C>
shader::GpuCluster clusterRecord(const C& c, uint32_t instance, uint32_t flags) {
  constexpr float kNoCone = 2.0f;
  return {glm::vec4(c.center, c.radius),
          glm::vec4(c.coneAxis, flags & CLUSTER_DOUBLE_SIDED ? kNoCone : c.coneCutoff),
          instance,
          c.firstTriangle,
          c.triangleCount,
          flags};
}
shader::GpuCluster triangleRunRecord(const Mesh& mesh, uint32_t first, uint32_t instance, uint32_t flags);
inline shader::GpuClusterLod lodRecord(const LodCluster& c) {
  return {c.sphere, c.parentSphere, glm::vec4(c.error, c.parentError, 0.0f, 0.0f)};
}
inline shader::GpuClusterLod alwaysInCut(glm::vec4 sphere) {  // its own error 0, no parent
  return {sphere, sphere, glm::vec4(0.0f, shader::LOD_ERROR_INFINITE, 0.0f, 0.0f)};
}
// The sphere around the box of `spheres` that holds each (rounded outwards).
glm::vec4 enclosingSphere(std::span<const glm::vec4> spheres);
// The same in steps, for spheres spread over pieces (render/mesh_records.cpp): each piece's box
// (extendBySphere), joined in order; each piece's farthest reach from the joined box's centre
// (sphereReach), the largest; then the sphere. The same bits as enclosingSphere over all of them.
inline void extendBySphere(Bounds& box, glm::vec4 s) { box.extend(glm::vec3(s) - s.w), box.extend(glm::vec3(s) + s.w); }
inline float sphereReach(const Bounds& box, glm::vec4 s) { return glm::length(glm::vec3(s) - box.center()) + s.w; }
glm::vec4 enclosingSphere(const Bounds& box, float reach);
// The culling tree over records [first, first + count), one level of a mesh (culling spheres in `clusters`,
// level-of-detail records in `lods`, or none): leaves of up to CULL_LEAF_SIZE consecutive records, nodes
// of up to CULL_NODE_CHILDREN (cluster.h). Its root goes to nodes[root] (the caller's slot), the rest is
// appended; adds its nodes at each depth (the root's 0) to `depthCounts`; returns its leaves.
uint32_t appendClusterTree(std::span<const shader::GpuCluster> clusters, std::span<const shader::GpuClusterLod> lods,
                           uint32_t first, uint32_t count, uint32_t root, std::vector<shader::GpuCullNode>& nodes,
                           std::vector<uint32_t>& depthCounts);
// appendClusterTree in steps, for a tree built in pieces (render/mesh_records.cpp). Its layers bottom up,
// layer 0 the leaves (their `first` a record), each node's `first` an index in the layer below:
// clusterTreeLayers makes the leaves and the layers above them up to one node, or exactly `nodeLayers`
// layers of nodes (a piece of CULL_LEAF_SIZE * CULL_NODE_CHILDREN^nodeLayers records: its subtree);
// addClusterTreeLayer makes one layer over the top one; storeClusterTree stores them as appendClusterTree
// does and returns the leaves.
using ClusterTreeLayers = std::vector<std::vector<shader::GpuCullNode>>;
ClusterTreeLayers clusterTreeLayers(std::span<const shader::GpuCluster> clusters, std::span<const shader::GpuClusterLod> lods,
                                    uint32_t first, uint32_t count, size_t nodeLayers = SIZE_MAX);
void addClusterTreeLayer(ClusterTreeLayers& layers);
uint32_t storeClusterTree(const ClusterTreeLayers& layers, uint32_t root, std::vector<shader::GpuCullNode>& nodes,
                          std::vector<uint32_t>& depthCounts);
// Every GpuCluster of a scene, numbered as GpuScene numbers its instances.
std::vector<shader::GpuCluster> gpuClusters(const Scene& scene);

// How DepthPyramid records its build: Levels, one dispatch and one barrier per level (hiz.comp,
// hiz_buffer.comp); Fused, up to HIZ_FUSED_LEVELS levels a dispatch (hiz_fused.glsl: two dispatches for
// CULL_PYRAMID_MAX_LEVELS). The same texels either way. RTR_PYRAMID_PASSES=levels|fused (default fused).
enum class PyramidPasses { Levels, Fused };
PyramidPasses pyramidPassesFromEnv();

// The farthest depth per texel of a depth image, level by level (level 0 half the image; which pixels a
// texel covers: shaders/shared/cull.h).
class DepthPyramid {
 public:
  DepthPyramid(const vk::Context& ctx, VkExtent2D depthExtent, PyramidPasses passes = pyramidPassesFromEnv());
  // Records the build from `depth` (a sampled view whose .r is depth: a D32 depth-aspect view or an R32F
  // image, in `depthLayout`, written before this by the compute or fragment stage with the barrier the
  // writer owes). Leaves the pyramid readable by compute shaders.
  void build(VkCommandBuffer cb, VkImageView depth, VkImageLayout depthLayout);
  // The same from the compute rasteriser's 64-bit visibility buffer (raster.h; depthExtent() pixels,
  // written by compute shaders before a barrier the writer owes), its level 0 read from the buffer directly.
  void buildFromBuffer(VkCommandBuffer cb, VkBuffer vis);
  VkImageView view() const { return image_.view(); }  // all levels, R32F, layout GENERAL
  VkExtent2D depthExtent() const { return depthExtent_; }
  uint32_t levels() const { return image_.mipLevels(); }
  const vk::Image& image() const { return image_; }
  static VkExtent2D pyramidExtent(VkExtent2D depth);  // level 0's
  PyramidPasses passes() const { return passes_; }
  uint32_t dispatches() const;  // the dispatches (and barriers) a build records

 private:
  const vk::Context& ctx_;
  VkExtent2D depthExtent_;
  vk::Image image_;
  std::vector<vk::ImageView> levelViews_;  // per level: storage (write) and sampled (read by the next level)
  PyramidPasses passes_;
  vk::Pipeline pipeline_, fromBuffer_;    // Levels (fromBuffer_: level 0 from a visibility buffer, made on first use)
  vk::Pipeline fused_, fusedFromBuffer_;  // Fused, the same way
  void begin(VkCommandBuffer cb);
  void buildLevels(VkCommandBuffer cb, const std::function<const vk::Pipeline&(VkImageView)>& bindLevel0);
  void buildFused(VkCommandBuffer cb, VkBuffer vis, VkImageView depth, VkImageLayout depthLayout);
  bool initialised_ = false;
};

struct CullCamera {
  glm::mat4 viewProj{1.0f};  // projectionMatrix * viewMatrix (src/core/camera.hpp)
  glm::vec3 eye{0.0f};
  bool orthographic = false;  // no cone test (it assumes rays from the eye)
  // The level-of-detail cut (with a GpuClusterLod buffer): pixels of projected error allowed, the image's
  // height / (2 tan(fovY / 2)), the near plane. A threshold of 0 or an orthographic camera: no cut
  // (the caller then passes only the full-detail clusters).
  float lodThreshold = 0.0f, pixelsPerUnit = 0.0f, zNear = 0.0f;
};

// Compute raster only: which clusters are tested before they are drawn (docs/culling.md); none changes the
// image. Frustum: one pass of the frustum and back-face cone tests (with the level-of-detail cut where one is
// drawn); TwoPhase: those and the depth pyramid's occlusion test, in two phases. Off: no test, but the cut
// alone where one is drawn. Auto: Frustum where a cut is drawn, else Off (the faster measured on the H200).
enum class Culling { Auto, Off, Frustum, TwoPhase };
constexpr std::array<EnumName<Culling>, 4> enumNames(Culling) {
  return {{{Culling::Auto, "auto"}, {Culling::Off, "off"}, {Culling::Frustum, "frustum"}, {Culling::TwoPhase, "on"}}};
}

struct CullTests {
  bool frustum = true, cone = true, occlusion = true;  // occlusion only when a pyramid is given
  bool lod = true;                                     // only with a GpuClusterLod buffer and a camera's threshold above 0
  bool nodes = true;  // prune the trees (off: every node descended, every cluster of the levels tested)
};

// Single: every cluster tested once (occlusion conservative only for the view the pyramid was built from).
// Early + Late: two-phase occlusion, conservative for any camera motion; per frame: record(Early), draw
// visible(), build the pyramid from that depth, record(Late) with it, draw visible() (the clusters Early
// did not list). The culler keeps the per-cluster history between frames (all "not visible" at first).
// A Late pass with Early's camera, tests and buffers re-tests Early's chunks (the tree leaves in the frustum
// and the cut) instead of walking the trees again: only the occlusion test and the history differ.
enum class CullPhase : uint32_t { Single = CULL_SINGLE, Early = CULL_EARLY, Late = CULL_LATE };

class ClusterCuller {
 public:
  // maxClusters: the (instance, cluster) pairs it may visit (list entries, history bits); maxChunks: the
  // runs of up to CULL_LEAF_SIZE clusters (tree leaves) it may emit (0: those of one instance of maxClusters, the
  // record() without instances); queueCapacity: per tree depth, the (instance, node) pairs at it
  // (GpuScene::cullQueueCapacity).
  ClusterCuller(const vk::Context& ctx, uint32_t maxClusters, uint32_t maxChunks = 0,
                const std::vector<uint32_t>& queueCapacity = {});
  // Records the pass over `count` GpuClusters in `clusters` (a storage buffer; the same clusters every
  // frame for Early/Late). With a pyramid (not used by Early), clusters hidden behind its depths are culled
  // too: a cluster whose every point lies behind that depth image there cannot be seen above it. Ends with
  // a barrier that makes visible() and counts() readable by compute shaders and indirect commands.
  // `lods`: the clusters' GpuClusterLod records (cluster.h), for the level-of-detail cut, tested first.
  // `instances`: GpuCullInstances (cluster.h), tested first (frustum), then the trees over their meshes'
  // levels (`nodes`: GpuCullNodes) down to the clusters that can be listed (docs/culling.md); the records
  // are placed by `placements` (GpuInstance, frame.h) as the instance says. None: one instance of the
  // first `count` clusters, records placed already (gpuClusters), never culled, no tree.
  void record(VkCommandBuffer cb, VkBuffer clusters, uint32_t count, const CullCamera& camera, const DepthPyramid* pyramid,
              CullTests tests = {}, CullPhase phase = CullPhase::Single, VkBuffer lods = VK_NULL_HANDLE,
              VkBuffer instances = VK_NULL_HANDLE, uint32_t instanceCount = 0, VkBuffer nodes = VK_NULL_HANDLE,
              VkBuffer placements = VK_NULL_HANDLE);
  // uvec2 (GpuInstance, GpuCluster record) per visible cluster, any order; Late's after Early's
  // (CullCounts::listBase).
  VkBuffer visible() const { return visible_.handle(); }
  VkBuffer counts() const { return counts_.handle(); }  // shader::CullCounts; offset 0 the dispatch args
  uint32_t maxClusters() const { return maxClusters_; }

 private:
  void walkTrees(VkCommandBuffer cb, shader::CullPush push, bool flat, uint32_t count, VkBuffer instances, uint32_t instanceCount,
                 VkBuffer nodes, VkBuffer placements);

  const vk::Context& ctx_;
  uint32_t maxClusters_, maxChunks_;
  vk::Buffer visible_, counts_, history_, chunks_;
  vk::Buffer whole_;           // the one GpuCullInstance of a record() without instances
  vk::Buffer items_, queues_;  // the trees' (instance, node) queues and their counts (CullQueue)
  std::array<uint32_t, CULL_MAX_DEPTH> queueBases_{};
  uint32_t depths_ = 0;
  // What decided the last Early pass's chunks (the leaves in the frustum and the cut, which do not depend on
  // the phase): a Late pass that matches it tests those chunks again without walking the trees a second
  // time. Any other pass forgets it. RTR_CULL_LATE_WALK=1: Late always walks (for measuring).
  struct Walk {
    glm::mat4 viewProj;
    glm::vec4 eye;
    uint32_t flags, count, instanceCount;
    float lodThreshold, pixelsPerUnit, zNear;
    VkBuffer clusters, lods, instances, nodes, placements;
    bool operator==(const Walk&) const = default;
  };
  std::optional<Walk> earlyWalk_;
  bool lateWalks_ = false;
  vk::Image noPyramid_;  // 1×1 stand-in so the pass always has a valid binding
  vk::Pipeline instancePipeline_, pipeline_;
};

}  // namespace rtr::render
