#include "render/cull.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <functional>
#include <string>

#include <glm/glm.hpp>

#include "core/env.hpp"
#include "core/error.hpp"
#include "scene/textures.hpp"
#include "vk/commands.hpp"
#include "vk/context.hpp"

namespace rtr::render {
namespace {

constexpr VkFormat kPyramidFormat = VK_FORMAT_R32_SFLOAT;

// Levels down to 1 × 1, at most CULL_PYRAMID_MAX_LEVELS (RTR_PYRAMID_LEVELS=N sets another cap, for
// measuring): each level is a dispatch and a barrier, and only boxes wider than the last level's texels
// reach past it (they read more of its texels instead).
uint32_t levelCount(VkExtent2D e) {
  uint32_t n = 1;
  for (uint32_t m = std::max(e.width, e.height); m > 1; m /= 2) ++n;
  return std::min(n, envNumber("RTR_PYRAMID_LEVELS", 1, 32, "a number of levels").value_or(CULL_PYRAMID_MAX_LEVELS));
}

}  // namespace

VkExtent2D DepthPyramid::pyramidExtent(VkExtent2D depth) {
  return {std::max(1u, depth.width / 2), std::max(1u, depth.height / 2)};
}

std::vector<Instance> gpuInstances(const Scene& scene) {
  std::vector<Instance> out = scene.instances;
  if (out.empty())
    for (uint32_t i = 0; i < scene.meshes.size(); ++i) out.push_back({i, glm::mat4(1.0f)});
  for (const Instance& in : out)
    if (in.mesh >= scene.meshes.size())
      throw Error("instance of mesh " + std::to_string(in.mesh) + ": the scene has " + std::to_string(scene.meshes.size()));
  std::erase_if(out, [&](const Instance& in) { return scene.meshes[in.mesh].indices.empty(); });
  std::stable_sort(out.begin(), out.end(), [](const Instance& a, const Instance& b) {
    return a.mesh != b.mesh ? a.mesh < b.mesh : !mirrored(a.transform) && mirrored(b.transform);
  });
  return out;
}

bool mirrored(const glm::mat4& t) { return glm::determinant(glm::mat3(t)) < 0.0f; }

uint32_t clusterFlags(const Mesh& m, const Material& mat) {
  if (m.texcoords.empty() || !(alphaTested(m, mat) || (mat.flags & kMaterialDoubleSided))) return 0;
  return CLUSTER_DOUBLE_SIDED | (mat.texture(TextureSlot::AlphaMask) != kNoTexture ? CLUSTER_ALPHA_MASKED : 0u);
}

std::pair<float, bool> largestStretch(const glm::mat4& transform) {
  // A column's length for a similarity, the Frobenius norm (>= the spectral norm) otherwise.
  const glm::mat3 l(transform);
  const glm::vec3 len(glm::length(l[0]), glm::length(l[1]), glm::length(l[2]));
  const float s = std::max(len.x, std::max(len.y, len.z)), eps = 1e-5f * s * s;
  const bool similarity = std::abs(len.x - len.y) <= 1e-5f * s && std::abs(len.x - len.z) <= 1e-5f * s &&
                          std::abs(glm::dot(l[0], l[1])) <= eps && std::abs(glm::dot(l[0], l[2])) <= eps &&
                          std::abs(glm::dot(l[1], l[2])) <= eps;
  return {similarity ? s : std::sqrt(glm::dot(len, len)), similarity};
}

namespace {

// Records [first, end) of `out` placed by `transform`.
void place(const glm::mat4& transform, size_t first, std::vector<shader::GpuCluster>& out) {
  const float noCone = 2.0f;
  if (transform == glm::mat4(1.0f)) return;
  const glm::mat3 l(transform);
  const auto [stretch, similarity] = largestStretch(transform);
  for (size_t i = first; i < out.size(); ++i) {
    shader::GpuCluster& c = out[i];
    c.sphere = glm::vec4(glm::vec3(transform * glm::vec4(glm::vec3(c.sphere), 1.0f)), c.sphere.w * stretch);
    // A mirror flips the winding and the front face with it (CLUSTER_MIRRORED), so the front normals
    // turn with the linear part in every case (its inverse transpose, parallel to it for a similarity).
    if (!similarity) c.cone = glm::vec4(0, 0, 1, noCone);
    else if (c.cone.w < 1.0f) c.cone = glm::vec4(glm::normalize(l * glm::vec3(c.cone)), c.cone.w);
  }
}

}  // namespace

shader::GpuCluster triangleRunRecord(const Mesh& m, uint32_t first, uint32_t instance, uint32_t flags) {
  constexpr float kNoCone = 2.0f;
  const uint32_t count = std::min<uint32_t>(CLUSTER_MAX_TRIANGLES, uint32_t(m.indices.size() / 3) - first);
  Bounds b;
  for (uint32_t i = 3 * first; i < 3 * (first + count); ++i) b.extend(m.positions[m.indices[i]]);
  const glm::vec3 c = 0.5f * (b.min + b.max);
  float r = 0.0f;
  for (uint32_t i = 3 * first; i < 3 * (first + count); ++i) r = std::max(r, glm::length(m.positions[m.indices[i]] - c));
  return {glm::vec4(c, r), glm::vec4(0, 0, 1, kNoCone), instance, first, count, flags};
}

void appendClusters(const Mesh& m, const glm::mat4& transform, uint32_t instance, uint32_t flags,
                    std::vector<shader::GpuCluster>& out) {
  const size_t first = out.size();
  for (const Cluster& c : m.clusters) out.push_back(clusterRecord(c, instance, flags));
  if (m.clusters.empty())
    for (uint32_t f = 0; f < m.indices.size() / 3; f += CLUSTER_MAX_TRIANGLES)
      out.push_back(triangleRunRecord(m, f, instance, flags));
  place(transform, first, out);
}

void appendClusterLods(const Mesh& m, const glm::mat4& transform, uint32_t instance, uint32_t flags, bool above, size_t first,
                       std::vector<shader::GpuCluster>& out, std::vector<shader::GpuClusterLod>& lods) {
  const size_t firstOut = out.size(), firstLod = lods.size();
  if (!above && m.lod.levels == 0) {
    for (size_t i = first; i < out.size(); ++i) lods.push_back(alwaysInCut(out[i].sphere));
    return;
  }
  for (const LodCluster& c : m.lod.clusters) {
    if ((c.level > 0) != above) continue;
    lods.push_back(lodRecord(c));
    if (above) out.push_back(clusterRecord(c, instance, flags));
  }
  if (above) place(transform, firstOut, out);
  if (transform == glm::mat4(1.0f)) return;
  const float stretch = largestStretch(transform).first;
  auto move = [&](glm::vec4 s) { return glm::vec4(glm::vec3(transform * glm::vec4(glm::vec3(s), 1.0f)), s.w * stretch); };
  auto scale = [&](float e) { return e >= shader::LOD_ERROR_INFINITE ? e : e * stretch; };
  for (size_t i = firstLod; i < lods.size(); ++i) {
    shader::GpuClusterLod& l = lods[i];
    l = {move(l.sphere), move(l.parentSphere), glm::vec4(scale(l.error.x), scale(l.error.y), 0.0f, 0.0f)};
  }
}

std::vector<shader::GpuCluster> gpuClusters(const Scene& scene) {
  std::vector<shader::GpuCluster> out;
  const std::vector<Instance> instances = gpuInstances(scene);
  for (uint32_t i = 0; i < instances.size(); ++i) {
    const Mesh& m = scene.meshes[instances[i].mesh];
    if (scene.materials.at(m.material).blended()) continue;  // the transparency pass draws it (GpuScene)
    const uint32_t flip = mirrored(instances[i].transform) ? CLUSTER_MIRRORED : 0u;
    appendClusters(m, instances[i].transform, i, clusterFlags(m, scene.materials.at(m.material)) | flip, out);
  }
  return out;
}

glm::vec4 enclosingSphere(const Bounds& box, float reach) {
  return box.empty() ? glm::vec4(0.0f) : glm::vec4(box.center(), reach * (1.0f + 1e-6f));  // rounding: never smaller
}

glm::vec4 enclosingSphere(std::span<const glm::vec4> spheres) {
  Bounds b;
  for (const glm::vec4& s : spheres) extendBySphere(b, s);
  float r = 0.0f;
  for (const glm::vec4& s : spheres) r = std::max(r, sphereReach(b, s));
  return enclosingSphere(b, r);
}

ClusterTreeLayers clusterTreeLayers(std::span<const shader::GpuCluster> clusters, std::span<const shader::GpuClusterLod> lods,
                                    uint32_t first, uint32_t count, size_t nodeLayers) {
  // Leaves of CULL_LEAF_SIZE consecutive records, then nodes of CULL_NODE_CHILDREN consecutive nodes.
  ClusterTreeLayers layers(1);
  std::vector<glm::vec4> spheres, lodSpheres;
  for (uint32_t at = first; at < first + count || (count == 0 && layers[0].empty()); at += CULL_LEAF_SIZE) {
    const uint32_t n = std::min<uint32_t>(CULL_LEAF_SIZE, first + count - at);
    shader::GpuCullNode leaf{{}, {}, lods.empty() ? 0.0f : shader::LOD_ERROR_INFINITE, 0.0f, at, n | CULL_NODE_LEAF};
    spheres.clear(), lodSpheres.clear();
    for (uint32_t c = at; c < at + n; ++c) {
      spheres.push_back(clusters[c].sphere);
      if (lods.empty()) continue;
      const shader::GpuClusterLod& l = lods[c];
      lodSpheres.push_back(l.sphere);
      if (l.error.y < shader::LOD_ERROR_INFINITE) lodSpheres.push_back(l.parentSphere);
      leaf.minError = std::min(leaf.minError, l.error.x);
      leaf.maxParentError = std::max(leaf.maxParentError, l.error.y);
    }
    if (lods.empty()) leaf.maxParentError = shader::LOD_ERROR_INFINITE;
    leaf.sphere = enclosingSphere(spheres);
    leaf.lodSphere = lods.empty() ? leaf.sphere : enclosingSphere(lodSpheres);
    layers[0].push_back(leaf);
    if (count == 0) break;
  }
  while (nodeLayers == SIZE_MAX ? layers.back().size() > 1 : layers.size() <= nodeLayers) addClusterTreeLayer(layers);
  return layers;
}

void addClusterTreeLayer(ClusterTreeLayers& layers) {
  const std::vector<shader::GpuCullNode>& below = layers.back();
  std::vector<shader::GpuCullNode> up;
  std::vector<glm::vec4> spheres, lodSpheres;
  for (uint32_t at = 0; at < below.size(); at += CULL_NODE_CHILDREN) {
    const uint32_t n = std::min<uint32_t>(CULL_NODE_CHILDREN, uint32_t(below.size()) - at);
    shader::GpuCullNode node{{}, {}, shader::LOD_ERROR_INFINITE, 0.0f, at, n};
    spheres.clear(), lodSpheres.clear();
    for (uint32_t c = at; c < at + n; ++c) {
      spheres.push_back(below[c].sphere), lodSpheres.push_back(below[c].lodSphere);
      node.minError = std::min(node.minError, below[c].minError);
      node.maxParentError = std::max(node.maxParentError, below[c].maxParentError);
    }
    node.sphere = enclosingSphere(spheres), node.lodSphere = enclosingSphere(lodSpheres);
    up.push_back(node);
  }
  layers.push_back(std::move(up));
}

uint32_t storeClusterTree(const ClusterTreeLayers& layers, uint32_t root, std::vector<shader::GpuCullNode>& nodes,
                          std::vector<uint32_t>& depthCounts) {
  // Stored top down: the root in its slot, each layer below in one run, parents pointed at their children.
  const size_t top = layers.size() - 1;
  if (depthCounts.size() < layers.size()) depthCounts.resize(layers.size(), 0);
  nodes[root] = layers[top][0];
  ++depthCounts[0];
  size_t parents = root;  // where the layer above was stored
  for (size_t k = top; k-- > 0;) {
    const uint32_t base = uint32_t(nodes.size());
    for (size_t j = 0; j < layers[k + 1].size(); ++j) nodes[parents + j].first += base;
    nodes.insert(nodes.end(), layers[k].begin(), layers[k].end());
    depthCounts[top - k] += uint32_t(layers[k].size());
    parents = base;
  }
  return uint32_t(layers[0].size());
}

uint32_t appendClusterTree(std::span<const shader::GpuCluster> clusters, std::span<const shader::GpuClusterLod> lods,
                           uint32_t first, uint32_t count, uint32_t root, std::vector<shader::GpuCullNode>& nodes,
                           std::vector<uint32_t>& depthCounts) {
  return storeClusterTree(clusterTreeLayers(clusters, lods, first, count), root, nodes, depthCounts);
}

PyramidPasses pyramidPassesFromEnv() {
  const char* v = std::getenv("RTR_PYRAMID_PASSES");
  if (!v || std::string(v) == "fused") return PyramidPasses::Fused;
  if (std::string(v) == "levels") return PyramidPasses::Levels;
  throw Error(std::string("RTR_PYRAMID_PASSES=") + v + ": levels or fused");
}

DepthPyramid::DepthPyramid(const vk::Context& ctx, VkExtent2D depthExtent, PyramidPasses passes)
    : ctx_(ctx), depthExtent_(depthExtent), passes_(passes) {
  vk::ImageDesc d;
  d.extent = pyramidExtent(depthExtent);
  d.format = kPyramidFormat;
  d.mipLevels = levelCount(d.extent);
  // Copies and clears: the tests read it back and poison it.
  d.usage =
      VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  d.name = "depth pyramid";
  image_ = vk::Image(ctx, d);
  for (uint32_t l = 0; l < d.mipLevels; ++l)
    levelViews_.push_back(image_.createView(kPyramidFormat, l, 1, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT));
  if (passes_ == PyramidPasses::Levels)
    pipeline_ = vk::makeComputePipeline(ctx, vk::loadShader("hiz.comp"), {.pushDescriptorSets = {0}});
  else fused_ = vk::makeComputePipeline(ctx, vk::loadShader("hiz_fused.comp"), {.pushDescriptorSets = {0}});
}

uint32_t DepthPyramid::dispatches() const {
  return passes_ == PyramidPasses::Levels ? levels() : (levels() + HIZ_FUSED_LEVELS - 1) / HIZ_FUSED_LEVELS;
}

void DepthPyramid::build(VkCommandBuffer cb, VkImageView depth, VkImageLayout depthLayout) {
  if (passes_ == PyramidPasses::Fused) return buildFused(cb, VK_NULL_HANDLE, depth, depthLayout);
  buildLevels(cb, [&](VkImageView level0) -> const vk::Pipeline& {
    pipeline_.bind(cb);
    vk::DescriptorWriter(ctx_, pipeline_.layout, 0, VK_NULL_HANDLE)
        .image(0, depth, depthLayout)
        .image(1, level0, VK_IMAGE_LAYOUT_GENERAL)
        .push(cb, pipeline_);
    return pipeline_;
  });
}

void DepthPyramid::buildFromBuffer(VkCommandBuffer cb, VkBuffer vis) {
  if (passes_ == PyramidPasses::Fused) return buildFused(cb, vis, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_UNDEFINED);
  if (!fromBuffer_.layout.handle())
    fromBuffer_ = vk::makeComputePipeline(ctx_, vk::loadShader("hiz_buffer.comp"), {.pushDescriptorSets = {0}});
  buildLevels(cb, [&](VkImageView level0) -> const vk::Pipeline& {
    fromBuffer_.bind(cb);
    vk::DescriptorWriter(ctx_, fromBuffer_.layout, 0, VK_NULL_HANDLE)
        .buffer(0, vis)
        .image(1, level0, VK_IMAGE_LAYOUT_GENERAL)
        .push(cb, fromBuffer_);
    fromBuffer_.push(cb, glm::uvec2(depthExtent_.width, depthExtent_.height));
    return fromBuffer_;
  });
}

void DepthPyramid::begin(VkCommandBuffer cb) {
  constexpr auto kCompute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
  constexpr auto kReadWrite = VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_SHADER_WRITE_BIT;
  if (!initialised_) {
    vk::barrier(cb, {{image_.handle(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_NONE, kCompute,
                      VK_ACCESS_2_NONE, kReadWrite}});
    initialised_ = true;
  } else {  // the last frame's culling read it
    vk::bufferBarrier(cb, vk::kComputeRead | vk::kCopyRead, vk::kComputeReadWrite);
  }
}

void DepthPyramid::buildLevels(VkCommandBuffer cb, const std::function<const vk::Pipeline&(VkImageView)>& bindLevel0) {
  begin(cb);
  for (uint32_t l = 0; l < levelViews_.size(); ++l) {
    const VkExtent2D e{std::max(1u, image_.extent().width >> l), std::max(1u, image_.extent().height >> l)};
    const vk::Pipeline* bound = &pipeline_;
    if (l == 0) {
      bound = &bindLevel0(levelViews_[0]);
    } else {
      if (l == 1) pipeline_.bind(cb);
      vk::DescriptorWriter(ctx_, pipeline_.layout, 0, VK_NULL_HANDLE)
          .image(0, levelViews_[l - 1], VK_IMAGE_LAYOUT_GENERAL)
          .image(1, levelViews_[l], VK_IMAGE_LAYOUT_GENERAL)
          .push(cb, pipeline_);
    }
    bound->dispatch(cb, e.width, e.height);
    // Each level is the next one's source; the last is the culling pass's (and a read-back's) input.
    vk::bufferBarrier(cb, vk::kComputeWrite, vk::kComputeRead | vk::kCopyRead);
  }
}

// A dispatch per HIZ_FUSED_LEVELS levels, one workgroup per HIZ_TILE × HIZ_TILE texels of its source (the
// depth or the visibility buffer, then the level below its first); each dispatch's levels are the next one's
// source.
void DepthPyramid::buildFused(VkCommandBuffer cb, VkBuffer vis, VkImageView depth, VkImageLayout depthLayout) {
  if (vis && !fusedFromBuffer_.layout.handle())
    fusedFromBuffer_ = vk::makeComputePipeline(ctx_, vk::loadShader("hiz_fused_buffer.comp"), {.pushDescriptorSets = {0}});
  begin(cb);
  const uint32_t levels = this->levels();
  for (uint32_t first = 0; first < levels; first += HIZ_FUSED_LEVELS) {
    const vk::Pipeline& p = first == 0 && vis ? fusedFromBuffer_ : fused_;
    const VkExtent2D src = first == 0 ? depthExtent_
                                      : VkExtent2D{std::max(1u, image_.extent().width >> (first - 1)),
                                                   std::max(1u, image_.extent().height >> (first - 1))};
    p.bind(cb);
    vk::DescriptorWriter w(ctx_, p.layout, 0, VK_NULL_HANDLE);
    if (first == 0 && vis) w.buffer(0, vis);
    else if (first == 0) w.image(0, depth, depthLayout);
    else w.image(0, levelViews_[first - 1], VK_IMAGE_LAYOUT_GENERAL);
    for (uint32_t j = 0; j < HIZ_FUSED_LEVELS; ++j)  // past the last level: bound, never written
      w.image(1 + j, levelViews_[std::min(first + j, levels - 1)], VK_IMAGE_LAYOUT_GENERAL);
    w.push(cb, p);
    p.push(cb, shader::HizPush{src.width, src.height, std::min<uint32_t>(HIZ_FUSED_LEVELS, levels - first), 0});
    vkCmdDispatch(cb, std::max(1u, src.width / HIZ_TILE), std::max(1u, src.height / HIZ_TILE), 1);
    vk::bufferBarrier(cb, vk::kComputeWrite, vk::kComputeRead | vk::kCopyRead);
  }
}

ClusterCuller::ClusterCuller(const vk::Context& ctx, uint32_t maxClusters, uint32_t maxChunks,
                             const std::vector<uint32_t>& queueCapacity)
    : ctx_(ctx),
      maxClusters_(maxClusters),
      maxChunks_(maxChunks ? maxChunks : (maxClusters + CULL_LEAF_SIZE - 1) / CULL_LEAF_SIZE) {
  // The pass's counters and lists take one atomic per subgroup (cull_subgroup.glsl).
  VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &subgroup};
  vkGetPhysicalDeviceProperties2(ctx.physicalDevice(), &props);
  constexpr VkSubgroupFeatureFlags kNeeded =
      VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT | VK_SUBGROUP_FEATURE_BALLOT_BIT;
  if (!(subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) || (subgroup.supportedOperations & kNeeded) != kNeeded)
    throw Error(std::string("cluster culling: ") + props.properties.deviceName +
                " has no subgroup arithmetic and ballot operations in compute shaders");
  if (queueCapacity.size() > CULL_MAX_DEPTH)
    throw Error("cluster culling: trees " + std::to_string(queueCapacity.size()) + " deep, at most " +
                std::to_string(CULL_MAX_DEPTH));
  uint64_t items = 0;
  for (size_t d = 0; d < queueCapacity.size(); ++d) queueBases_[d] = uint32_t(items), items += queueCapacity[d];
  if (items > UINT32_MAX / 8) throw Error("cluster culling: " + std::to_string(items) + " tree nodes over the instances");
  depths_ = uint32_t(queueCapacity.size());
  items_ = vk::Buffer(ctx, std::max<VkDeviceSize>(8, items * 8), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUse::Device,
                      "cull tree queues");
  queues_ =
      vk::Buffer(ctx, sizeof(shader::CullQueue) * CULL_MAX_DEPTH,
                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                 vk::MemoryUse::Device, "cull tree queue counts");
  visible_ = vk::Buffer(ctx, std::max<VkDeviceSize>(8, VkDeviceSize(maxClusters) * 8),
                        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUse::Device,
                        "visible clusters");
  counts_ = vk::Buffer(ctx, sizeof(shader::CullCounts),
                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                           VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                       vk::MemoryUse::Device, "cull counts");
  history_ =
      vk::Buffer(ctx, 4 * (VkDeviceSize(maxClusters) / 32 + 1),
                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Device, "cluster history");
  chunks_ = vk::Buffer(ctx, std::max<VkDeviceSize>(16, VkDeviceSize(maxChunks_) * 16), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                       vk::MemoryUse::Device, "cluster chunks");
  whole_ = vk::Buffer(ctx, sizeof(shader::GpuCullInstance), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                      vk::MemoryUse::Device, "all clusters as one instance");
  vk::ImageDesc d;
  d.format = kPyramidFormat;
  d.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
  d.name = "no depth pyramid";
  noPyramid_ = vk::Image(ctx, d);
  vk::submitAndWait(ctx, [&](VkCommandBuffer cb) {
    vkCmdFillBuffer(cb, history_.handle(), 0, VK_WHOLE_SIZE, 0);  // no cluster was visible before
    vk::bufferBarrier(cb, vk::kTransferWrite, vk::kComputeReadWrite);
    vk::barrier(cb, {{noPyramid_.handle(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_NONE,
                      VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_NONE, VK_ACCESS_2_SHADER_READ_BIT}});
  });
  const char* walks = std::getenv("RTR_CULL_LATE_WALK");
  lateWalks_ = walks && std::string(walks) == "1";
  pipeline_ = vk::makeComputePipeline(ctx, vk::loadShader("cull.comp"), {.pushDescriptorSets = {0}});
  instancePipeline_ = vk::makeComputePipeline(ctx, vk::loadShader("cull_instances.comp"), {.pushDescriptorSets = {0}});
}

// The instances, then the trees depth by depth (each step's queue filled by the one before), into the chunks.
void ClusterCuller::walkTrees(VkCommandBuffer cb, shader::CullPush push, bool flat, uint32_t count, VkBuffer instances,
                              uint32_t instanceCount, VkBuffer nodes, VkBuffer placements) {
  instancePipeline_.bind(cb);
  vk::DescriptorWriter(ctx_, instancePipeline_.layout, 0, VK_NULL_HANDLE)
      .buffer(1, counts_.handle())
      .buffer(6, instances)
      .buffer(7, chunks_.handle())
      .buffer(8, nodes ? nodes : instances)  // not read without a tree
      .buffer(9, placements ? placements : instances)
      .buffer(10, queues_.handle())
      .buffer(11, items_.handle())
      .push(cb, instancePipeline_);
  push.depth = CULL_INSTANCE_STEP;
  instancePipeline_.push(cb, push);
  instancePipeline_.dispatch(cb, flat ? (count + CULL_LEAF_SIZE - 1) / CULL_LEAF_SIZE : instanceCount);
  for (uint32_t d = 0; nodes && d < depths_; ++d) {
    vk::bufferBarrier(cb, vk::kComputeWrite, vk::kComputeReadWrite | vk::kIndirectRead);
    push.depth = d;
    instancePipeline_.push(cb, push);
    vkCmdDispatchIndirect(cb, queues_.handle(), d * sizeof(shader::CullQueue));
  }
}

void ClusterCuller::record(VkCommandBuffer cb, VkBuffer clusters, uint32_t count, const CullCamera& camera,
                           const DepthPyramid* pyramid, CullTests tests, CullPhase phase, VkBuffer lods, VkBuffer instances,
                           uint32_t instanceCount, VkBuffer nodes, VkBuffer placements) {
  if (count > maxClusters_ || (!instances && (count + CULL_LEAF_SIZE - 1) / CULL_LEAF_SIZE > maxChunks_))
    throw Error("cluster culling: " + std::to_string(count) + " clusters, room for " + std::to_string(maxClusters_));
  constexpr vk::BufferUse kConsumers = vk::kComputeRead | vk::kIndirectRead | vk::kCopyRead;
  const bool flat = !instances;
  if (flat) {  // one instance of records placed already, never culled
    instances = whole_.handle(), instanceCount = 1, nodes = VK_NULL_HANDLE;
  } else if (!nodes) {
    throw Error("cluster culling: instances without their trees");
  }

  shader::CullPush push{};
  push.viewProj = camera.viewProj;
  push.eye = glm::vec4(camera.eye, 1.0f);
  push.count = instanceCount;
  push.flags = (tests.frustum ? CULL_FRUSTUM : 0u) | (tests.cone && !camera.orthographic ? CULL_CONE : 0u) |
               (tests.occlusion && pyramid ? CULL_OCCLUSION : 0u) |
               (tests.lod && lods && camera.lodThreshold > 0.0f && !camera.orthographic ? CULL_LOD : 0u) |
               (tests.nodes ? CULL_NODES : 0u);
  push.clusters = flat ? count : 0;
  push.lodThreshold = camera.lodThreshold;
  push.pixelsPerUnit = camera.pixelsPerUnit;
  push.zNear = camera.zNear;
  push.phase = uint32_t(phase);
  push.maxGroupsX = std::min(ctx_.properties().limits.maxComputeWorkGroupCount[0], 65535u);
  if (pyramid) {
    push.width = pyramid->depthExtent().width;
    push.height = pyramid->depthExtent().height;
    push.pyramidLevels = pyramid->levels();
  }
  // Early's chunks serve a Late pass that walks the same trees the same way (occlusion aside: Early has no pyramid).
  const Walk walk{push.viewProj,
                  push.eye,
                  push.flags & ~CULL_OCCLUSION,
                  count,
                  instanceCount,
                  push.lodThreshold,
                  push.pixelsPerUnit,
                  push.zNear,
                  clusters,
                  lods,
                  instances,
                  nodes,
                  placements};
  const bool reuse = phase == CullPhase::Late && !lateWalks_ && earlyWalk_ == walk;
  earlyWalk_.reset();  // only the pass right after Early may reuse its chunks (placements may change by the next frame)
  if (phase == CullPhase::Early) earlyWalk_ = walk;

  // The last frame's consumers are done with both buffers before they are reset and rewritten.
  vk::bufferBarrier(cb, kConsumers, vk::kTransferWrite);
  // Late appends to Early's list: its entries start where Early's end (the early ones stay valid).
  // Reusing Early's chunks keeps them, their dispatch and the counts of the walk (clusters in them,
  // instances culled whole); the nodes tested in this pass are none.
  size_t reset = sizeof(shader::CullCounts);
  if (phase == CullPhase::Late) {
    const VkBufferCopy base{offsetof(shader::CullCounts, listed), offsetof(shader::CullCounts, listBase), 4};
    vkCmdCopyBuffer(cb, counts_.handle(), counts_.handle(), 1, &base);
    vk::bufferBarrier(cb, vk::kTransferWrite | vk::kCopyRead, vk::kTransferWrite);
    reset = reuse ? offsetof(shader::CullCounts, tested) : offsetof(shader::CullCounts, listBase);
  }
  const shader::CullCounts zero{{0, 1, 1}, {0, 0, 0, 0}, 0, 0, 0, 0, 0, {0, 1, 1}, 0, 0, 0, 0, 0};  // dispatches' y, z: 1
  vkCmdUpdateBuffer(cb, counts_.handle(), 0, reset, &zero);
  if (reuse) vkCmdUpdateBuffer(cb, counts_.handle(), offsetof(shader::CullCounts, nodes), 4, &zero.nodes);
  if (flat) {
    const shader::GpuCullInstance all{glm::vec4(0.0f, 0.0f, 0.0f, 1e30f), glm::vec4(0.0f, 0.0f, 0.0f, 1e30f),
                                      glm::uvec4(0, 1, CULL_RECORD_INSTANCE, 0), glm::vec4(1.0f, 1.0f, 1.0f, 0.0f)};
    vkCmdUpdateBuffer(cb, whole_.handle(), 0, sizeof(all), &all);
  }
  if (!reuse) {
    std::array<shader::CullQueue, CULL_MAX_DEPTH> queues{};
    for (uint32_t d = 0; d < CULL_MAX_DEPTH; ++d) queues[d] = {{0, 1, 1}, 0, queueBases_[d], 0, 0, 0};
    vkCmdUpdateBuffer(cb, queues_.handle(), 0, sizeof(queues), queues.data());
  }
  vk::bufferBarrier(cb, vk::kTransferWrite, vk::kComputeReadWrite);
  if (!reuse) walkTrees(cb, push, flat, count, instances, instanceCount, nodes, placements);

  vk::bufferBarrier(cb, vk::kComputeWrite, vk::kComputeReadWrite | vk::kIndirectRead);
  pipeline_.bind(cb);
  vk::DescriptorWriter(ctx_, pipeline_.layout, 0, VK_NULL_HANDLE)
      .buffer(0, clusters)
      .buffer(1, counts_.handle())
      .buffer(2, visible_.handle())
      .image(3, pyramid ? pyramid->view() : noPyramid_.view(), VK_IMAGE_LAYOUT_GENERAL)
      .buffer(4, history_.handle())
      .buffer(5, lods ? lods : clusters)  // not read without CULL_LOD
      .buffer(6, instances)
      .buffer(7, chunks_.handle())
      .buffer(9, placements ? placements : clusters)  // not read for CULL_RECORD_INSTANCE
      .push(cb, pipeline_);
  pipeline_.push(cb, push);
  vkCmdDispatchIndirect(cb, counts_.handle(), offsetof(shader::CullCounts, chunkDispatch));
  vk::bufferBarrier(cb, vk::kComputeWrite, kConsumers | vk::kComputeWrite);
}

}  // namespace rtr::render
