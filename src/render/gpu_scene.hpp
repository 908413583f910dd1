#pragma once
// A scene on the GPU: vertex streams, index buffers (16-bit where a mesh allows; both also readable as
// storage buffers by the visibility path's shading pass), the material and draw buffers, and the textures
// that some drawn material uses (decoded on all cores, uploaded batch by batch through one staging ring,
// mips generated on the GPU, or under MipMode::Auto on the CPU for small ones; baked and cached chains
// unpacked straight into the ring: render/textures.cpp).
// Geometry is written on all cores straight into device-local memory where the host can write it (Direct),
// or into a ring of staging slots that the GPU copies into place (Staged). Nothing unused is created.
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <future>
#include <functional>
#include <list>
#include <vector>

#include "core/enum_names.hpp"
#include "frame.h"
#include "render/mips.hpp"
#include "scene/scene.hpp"
#include "scene/texture_cache.hpp"
#include "vk/commands.hpp"
#include "vk/resources.hpp"

namespace rtr {
class ThreadPool;
}
namespace rtr::vk {
class Context;
}

namespace rtr::render {

// Which scene pipeline draws a mesh: the textured opaque one, the one without texcoords, or the
// alpha-masked, double-sided one.
enum class DrawKind { Opaque, Untextured, AlphaMasked, Count };
constexpr size_t kDrawKindCount = size_t(DrawKind::Count);

// One instanced draw: a mesh under a range of instances (all mirrored or none: the front face is per draw).
struct DrawItem {
  uint32_t material = 0;
  uint32_t indexCount = 0;  // the mesh's own triangles (what a hardware draw draws)
  uint32_t primitives = 0;  // triangles its ids may name: the mesh's, then its hierarchy's (Mesh::lod)
  uint32_t firstIndex = 0;  // in the index buffer of its type
  int32_t vertexOffset = 0;
  VkIndexType indexType = VK_INDEX_TYPE_UINT32;
  uint32_t id = 0;                                // index of its mesh's GpuDraw in drawInfo()
  uint32_t firstInstance = 0, instanceCount = 1;  // range of the instance buffer (gl_InstanceIndex)
  bool mirrored = false;                          // its instances flip the winding: front faces are clockwise
  glm::vec3 center{0.0f};                         // of its instances' scene-space box (frames draw the nearest first)
};
// A draw of a glTF BLEND material: one instance each (the transparency pass sorts them per frame), in
// neither draws() nor the clusters (they write no visibility id or depth).
struct BlendDraw {
  DrawItem item;
  bool textured = false, doubleSided = false;
};
struct GeometryPlan;

// How the geometry reaches device memory (docs/startup.md, "Geometry upload"): Direct (and Auto, the
// same), written by the CPU in place where the host can map it, the fastest way measured on every device
// (docs/startup.md, "What the bus allows"); a buffer that is not mappable (no large BAR) goes through a
// ring of host staging slots that the GPU copies (DMA) while the next slots are written. Staged sends
// every buffer that way: what tests and rtr-bench-upload use to run and measure that path.
enum class GeometryUpload { Auto, Direct, Staged };
constexpr std::array<EnumName<GeometryUpload>, 3> enumNames(GeometryUpload) {
  return {{{GeometryUpload::Auto, "auto"}, {GeometryUpload::Direct, "direct"}, {GeometryUpload::Staged, "staged"}}};
}

// What a renderer's pipelines and its choice of path depend on, of a scene: its kinds, not its bytes.
// sceneKinds() computes them from the Scene (no GPU, microseconds), so that the pipelines can be made while
// the scene uploads (Renderer::prepare); GpuScene::kinds() gives them from what the upload made, and the
// two are equal (render_test SceneKindsAreWhatTheUploadMakes).
struct SceneKinds {
  std::array<bool, kDrawKindCount> draws{};  // by DrawKind: some instance draws a mesh of that kind
  bool blended = false;                      // glTF BLEND draws (the transparency pass)
  bool texcoords = false;                    // some mesh has texture coordinates (the stream exists)
  bool materialExtras = false;               // GpuScene::materialExtras
  uint32_t textures = 0;                     // textures a drawn material samples: the layouts' array sizes
  uint32_t instances = 0;                    // drawn placements (GpuInstance records)
  uint64_t triangles = 0;                    // of every drawn instance, blended ones aside
  uint64_t visIds = 0;                       // GpuScene::visIdCount
  bool clusterIdsFit = true;                 // the compute rasteriser's lists can name every (instance, cluster) record
  bool identityInstances = true;             // every instance's transform is the identity (shade's IDENTITY variant)
  bool operator==(const SceneKinds&) const = default;
};
SceneKinds sceneKinds(const Scene& scene);

// The loading phases, in order; they do not overlap, and together they are the constructor's time
// (pipeline creation for the mips aside, which the context's pipeline cache counts), but for a waited-for
// load's decode, which runs beside the geometry (decodeBesideMs of decodeMs; decodeWaitMs waited for it after).
struct GpuSceneStats {
  uint32_t meshes = 0, triangles = 0, vertices = 0, textures = 0, meshes16 = 0;  // stored once each
  uint32_t instances = 0;                                                        // placements drawn (GpuInstance records)
  double decodeMs = 0;              // texture files decoded on all cores, into staging memory
  double decodeBesideMs = 0;        // of decodeMs: the decode beside the geometry upload (TextureLoad::Wait)
  double decodeWaitMs = 0;          // waiting for that decode once the geometry was in
  double geometryMs = 0;            // vertex and index streams laid out, written and (where needed) copied
  double textureUploadMs = 0;       // staging memory to level 0 of each texture
  double mipsMs = 0, mipGpuMs = 0;  // mip chains: wall time, and the GPU's share of it
  uint32_t imagesDecoded = 0;       // textures decoded from their images (neither baked nor a cache hit)
  uint32_t cacheHits = 0;           // textures whose chains came from the texture cache (no decode, no mips)
  uint32_t cacheMisses = 0;         // textures looked up and not found: their chains are read back and stored
  double cacheReadbackMs = 0;       // reading those chains back (their packing and writing runs on a worker thread)
  uint32_t uploadBatches = 0;       // submissions of texel copies (one per batch through the staging ring)
  uint32_t stagingAllocations = 0;  // staging buffers made for textures (the ring's: 1 unless a texture outgrew it)
  size_t stagingBytes = 0;          // their size
  size_t geometryBytes = 0;
  GeometryUpload geometryUpload = GeometryUpload::Direct;  // the path taken (Direct or Staged)
  uint32_t geometryCopies = 0;                             // copy submissions from the geometry's staging ring
  // Where a Staged upload's time went (ms): the ring made; the writing threads' waits for a slot still
  // read by earlier copies, summed over threads, and the wait for the last copies; the submissions.
  double geometryRingMs = 0, geometryWaitMs = 0, geometrySubmitMs = 0;
  // geometryMs by phase: the plan; the streams' buffers made (and mapped); the streams written and the
  // records made beside them (the longest single mesh's records: geometryLongestBuildMs); the records
  // placed, their buffers made and written. What is left of geometryMs is the materials and kinds.
  double geometryPlanMs = 0, geometryBuffersMs = 0, geometryStreamsMs = 0, geometryLongestBuildMs = 0, geometryRecordsMs = 0;
};

// Told how far a long load is: what it does, how many of how many are done (serialised calls).
using LoadProgress = std::function<void(const char* what, size_t done, size_t total)>;

// How the scene's textures are sampled (the brief's mip experiments, task 1.4): trilinear; the nearest mip
// level, filtered linearly within it; or nearest texel of the nearest level. Anisotropy 1 is off.
enum class TextureFilter { Trilinear, NearestMip, Nearest };
constexpr std::array<EnumName<TextureFilter>, 3> enumNames(TextureFilter) {
  return {
      {{TextureFilter::Trilinear, "trilinear"}, {TextureFilter::NearestMip, "nearest-mip"}, {TextureFilter::Nearest, "nearest"}}};
}
struct SamplerSettings {
  TextureFilter filter = TextureFilter::Trilinear;
  float anisotropy = 1.0f;
  bool operator==(const SamplerSettings&) const = default;
};
// The largest anisotropy the device samples with: 1 without the samplerAnisotropy feature.
float maxAnisotropy(const vk::Context& ctx);
// A sampler for a scene texture: wrap modes from `desc` (the texture's own, glTF samplers; OBJ textures
// repeat), filters from `desc` under Trilinear (the texture's own; OBJ: trilinear), forced nearest-mip or
// nearest by the other settings (the mip experiments apply to every texture); the anisotropy is clamped
// to maxAnisotropy(ctx).
vk::Sampler makeSampler(const vk::Context& ctx, const SamplerSettings& settings, const SamplerDesc& desc = {});

// Whether the constructor returns with the textures on the GPU (Wait), or leaves them decoding on worker
// threads (Deferred): updateTextures() takes them in as they are decoded, a batch at a time; until its
// texture is in, a material's slot shows its factor alone.
enum class TextureLoad { Wait, Deferred };

class StagingRing;

class GpuScene {
 public:
  // `scene` and `progress` must outlive a Deferred texture load (or the object).
  // `cache` (it too must outlive the object): textures read from files or glTF images are looked up there
  // first (a hit: the chain as this device made it, uploaded whole), and the chains of those not found are
  // stored once the GPU has made them (read back, then packed and written on a worker thread).
  // `uploadBudget`: bytes of texels per upload batch (setUploadBudget), which sizes the staging ring.
  // `geometrySlotBytes`: the slots of a Staged geometry upload's ring (tests make them small).
  GpuScene(const vk::Context& ctx, const Scene& scene, MipMode mips, const LoadProgress& progress = {},
           GeometryUpload upload = GeometryUpload::Auto, TextureLoad textures = TextureLoad::Wait, TextureCache* cache = nullptr,
           size_t uploadBudget = kDefaultUploadBudget, size_t geometrySlotBytes = kGeometrySlotBytes);
  ~GpuScene();
  GpuScene(const GpuScene&) = delete;
  GpuScene& operator=(const GpuScene&) = delete;

  // Deferred load, between frames. Takes in the textures decoded so far, a batch at a time: at most one
  // batch in flight, of the textures decoded first, up to uploadBudget() bytes of staged texels (at least
  // one texture); its upload and mips go in a submission of their own. Once that has completed, the
  // materials' slots point at its textures: a copy into the material buffer, submitted before the next
  // frame (frames in flight keep reading the old slots; no wait). Renderers see textureArrivals() change
  // and write the new textures' descriptors, which no pending frame uses. True once, when the last texture
  // is in; `wait`: blocks until then.
  bool updateTextures(bool wait = false);
  bool texturesReady() const { return ready_; }
  size_t texturesDecoded() const { return decoded_; }  // of textureCount(), while loading
  size_t texturesIn() const { return texturesIn_; }    // on the GPU, their materials pointing at them
  bool textureIn(uint32_t gpuIndex) const { return in_.at(gpuIndex) != 0; }
  uint64_t textureArrivals() const { return arrivals_; }  // changes whenever textures came in
  // The per-batch budget (bytes of staged texels, every level included; a waited load's batches too). The
  // staging ring holds two batches; a change after the first batch changes the batches, not the ring.
  static constexpr size_t kDefaultUploadBudget = size_t(16) << 20;
  // The geometry's staging ring (a Staged upload): kGeometrySlots slots of kGeometrySlotBytes (a piece larger
  // than a slot makes them that large), freed once the upload is done.
  static constexpr size_t kGeometrySlotBytes = size_t(32) << 20;
  static constexpr uint32_t kGeometrySlots = 4;
  static constexpr vk::MemoryUse kGeometryRingMemory = vk::MemoryUse::Upload;  // written once, in order
  void setUploadBudget(size_t bytes) { uploadBudget_ = bytes; }

  const std::vector<DrawItem>& draws(DrawKind k) const { return draws_[size_t(k)]; }
  bool hasDraws(DrawKind k) const { return !draws_[size_t(k)].empty(); }
  const std::vector<BlendDraw>& blendDraws() const { return blendDraws_; }
  VkBuffer positions() const { return positions_.handle(); }
  VkBuffer normals() const { return normals_.handle(); }
  VkBuffer texcoords() const { return texcoords_.handle(); }  // null when no mesh has texcoords
  // glTF's streams, read as storage buffers by gl_VertexIndex; null where no mesh has them.
  VkBuffer texcoords1() const { return texcoords1_.handle(); }
  VkBuffer tangents() const { return tangents_.handle(); }
  VkBuffer colors() const { return colors_.handle(); }
  // Whether some draw needs what glTF adds to a material (texture transforms, the second uv set, vertex
  // colours, tangents, normal and occlusion maps, unlit, GGX): the shading pass's MATERIAL_EXTRAS variant.
  bool materialExtras() const { return materialExtras_; }
  // Whether every instance is the identity (a scene without instances): the shading pass's IDENTITY variant.
  bool identityInstances() const { return identityInstances_; }
  SceneKinds kinds() const;  // as uploaded: sceneKinds() of the scene
  VkBuffer indices16() const { return indices16_.handle(); }
  VkBuffer indices32() const { return indices32_.handle(); }
  VkBuffer materials() const { return materials_.handle(); }
  VkBuffer drawInfo() const { return drawInfo_.handle(); }    // GpuDraw per draw, for shading in compute
  VkBuffer instances() const { return instances_.handle(); }  // GpuInstance (frame.h), gpuInstances() order
  uint32_t instanceCount() const { return stats_.instances; }
  // GpuCluster (cluster.h) per cluster of each mesh, in the mesh's space (docs/culling.md): its full-detail
  // clusters, then those of its hierarchy above level 0; the culling pass places them per instance.
  VkBuffer clusters() const { return clusters_.handle(); }
  uint32_t clusterCount() const { return clusterCount_; }          // (instance, cluster) pairs, every level
  uint32_t baseClusterCount() const { return baseClusterCount_; }  // (instance, cluster) pairs of level 0
  // uvec2 (GpuInstance, GpuCluster) per pair of level 0, instance by instance: what the compute rasteriser
  // draws without the culling pass (raster_fetch.glsl's clusterList).
  VkBuffer baseEntries() const { return baseEntries_.handle(); }
  uint32_t chunkCapacity() const { return chunkCapacity_; }  // the culling pass's chunks at most (ClusterCuller)
  // GpuCullInstance (cluster.h) per instance with clusters: its spheres, its mesh's levels, its placement.
  VkBuffer cullInstances() const { return cullInstances_.handle(); }
  uint32_t cullInstanceCount() const { return cullInstanceCount_; }
  // GpuCullNode (cluster.h): each mesh's trees over its levels, the roots first (level 0's, then above).
  VkBuffer cullNodes() const { return cullNodes_.handle(); }
  // Per tree depth, the (instance, node) pairs at it: the culling pass's queues (ClusterCuller).
  const std::vector<uint32_t>& cullQueueCapacity() const { return cullQueueCapacity_; }
  // GpuClusterLod per GpuCluster where some mesh has a hierarchy (docs/virtual-geometry.md); else null.
  VkBuffer clusterLods() const { return clusterLods_.handle(); }
  // Visibility ids (frame.h): instance i names the ids [firstId(i), firstId(i) + its draw's primitives),
  // instances in order, blended ones none. They fit a frame's 32 bits while visIdCount() <= kMaxVisIds;
  // visIdPages() (uint per page of 2^visIdPageShift() ids, the instance holding the page's first id, then
  // one more) finds an id's instance in a few steps.
  static constexpr uint64_t kMaxVisIds = 0xFFFFFFFFu;  // VIS_EMPTY is no id
  uint64_t visIdCount() const { return visIdCount_; }
  uint64_t firstId(uint32_t instance) const { return firstIds_.at(instance); }
  VkBuffer visIdPages() const { return visIdPages_.handle(); }
  uint32_t visIdPageShift() const { return idPageShift_; }
  // The instance and the primitive (of its draw) an id names (the CPU's decode, for tests and tools).
  std::pair<uint32_t, uint32_t> decodeVisId(uint32_t id) const;
  uint32_t textureCount() const { return stats_.textures; }  // also while they load
  // Every texture's view; null where it is not in yet. The renderer pairs them with samplers.
  std::vector<VkImageView> textureViews() const;
  const std::vector<SamplerDesc>& textureSamplers() const { return samplers_; }  // per texture, its own
  const Bounds& bounds() const { return bounds_; }
  const GpuSceneStats& stats() const { return stats_; }
  // Every geometry buffer by name (null where the scene needs none): tests compare two uploads' bytes.
  std::vector<std::pair<const char*, const vk::Buffer*>> geometryBuffers() const;

 private:
  // Decodes, or starts to: a deferred load's decode in decoding_, a waited-for one's in `beside` (to be
  // waited for after the geometry upload), else here.
  std::vector<uint32_t> startTextures(const Scene& scene, TextureLoad load, std::future<void>& beside);
  GeometryPlan planGeometry(const Scene& scene);              // the streams' layout and the draws
  void placeRecords(const Scene& scene, GeometryPlan& plan);  // once made: draws_, instances, ids
  std::vector<shader::GpuMaterial> gpuMaterials(const Scene& scene, const std::vector<uint32_t>& gpuIndex) const;
  // Streams written and records made on all cores, then placed and written.
  void uploadGeometry(const Scene& scene, GeometryPlan& plan, const std::vector<shader::GpuMaterial>& materials,
                      GeometryUpload upload, size_t slotBytes, std::future<std::unique_ptr<StagingRing>> ringMade);
  void finishTextures();                                 // staging buffers to images, mips (a waited load)
  std::vector<uint32_t> nextBatch(bool wait);            // a deferred load's next textures, by the budget
  void startUpload(const std::vector<uint32_t>& batch);  // the same in one submission, not waited for
  void takeIn();                                         // its submission completed: the materials point at them
  void createTexture(uint32_t i);
  size_t batchEnd(const std::vector<uint32_t>& queue, size_t first) const;  // a batch from `first`, by the budget
  // Writes the batch's texels into a slot of the staging ring on all cores and submits their copies, then
  // what `after` records; returns that submission (the ring's, until the slot is taken again).
  const vk::Submission& submitBatch(const std::vector<uint32_t>& batch, const std::function<void(VkCommandBuffer)>& after);
  void recordUpload(VkCommandBuffer cb, const std::vector<uint32_t>& which, const std::vector<VkDeviceSize>& at) const;
  // The chains of the textures the cache missed: read back, then stored (the cache trimmed after the last).
  void storeInCache(std::vector<std::pair<uint32_t, TextureCacheKey>> which, bool last);

  const vk::Context& ctx_;
  MipMode mipMode_;
  LoadProgress progress_;
  struct Staged {                              // a texture's texels until its batch is written into the staging ring
    std::shared_ptr<const BakedTexels> chain;  // baked or a cache hit: its pieces unpacked into the ring
    std::vector<uint8_t> texels;               // else decoded: level 0, or the chain made on the CPU
    size_t bytes = 0;
    VkExtent2D extent;
    std::vector<VkDeviceSize> levels;  // a whole chain (baked, cached, made on the CPU): each level's offset; else empty
  };
  std::vector<bool> hostMips_;  // per texture: its whole chain came with it (uploaded whole, no mip pass)
  std::vector<const vk::Image*> gpuMipBatch(const std::vector<uint32_t>& which) const;  // chains the GPU makes
  std::vector<Staged> staged_;                                                          // texels, until uploaded
  std::vector<VkFormat> formats_;                                                       // of each texture
  std::vector<shader::GpuMaterial> texturedMaterials_;  // a deferred load's materials, as they will be
  std::vector<shader::GpuMaterial> shownMaterials_;     // and as the material buffer holds them meanwhile
  std::atomic<size_t> decoded_{0};
  std::future<void> decoding_;  // a deferred load's decode, until taken in
  std::mutex decodedMutex_;     // guards the two below, written by the decoding threads
  std::condition_variable decodedChanged_;
  std::vector<uint32_t> decodedQueue_;  // decoded and staged, not yet in a batch, in decode order
  bool decodeFinished_ = false;
  std::vector<uint8_t> in_;  // per texture: on the GPU and in the materials
  size_t texturesIn_ = 0;
  uint64_t arrivals_ = 0;
  size_t uploadBudget_ = kDefaultUploadBudget;
  double fillMs_ = 0;  // writing batches into the staging ring (a waited load counts it as decode)
  TextureCache* cache_ = nullptr;
  std::string cacheVariant_;                               // what makes this device's chains (the cache key)
  std::vector<std::optional<TextureCacheKey>> storeKeys_;  // per texture: a cache miss, stored once its chain is made
  std::vector<std::future<void>> storing_;                 // packing and writing them
  bool materialExtras_ = false;
  bool identityInstances_ = false;
  bool ready_ = false;  // every texture is on the GPU and the materials point at them
  std::array<std::vector<DrawItem>, kDrawKindCount> draws_;
  std::vector<BlendDraw> blendDraws_;
  vk::Buffer positions_, normals_, texcoords_, indices16_, indices32_, materials_, drawInfo_, instances_, clusters_;
  vk::Buffer texcoords1_, tangents_, colors_, clusterLods_, visIdPages_, cullInstances_, cullNodes_, baseEntries_;
  uint32_t clusterCount_ = 0, baseClusterCount_ = 0, cullInstanceCount_ = 0, chunkCapacity_ = 0;
  std::vector<uint32_t> cullQueueCapacity_;
  std::vector<uint64_t> firstIds_;  // per instance
  uint64_t visIdCount_ = 0;
  uint32_t idPageShift_ = 0;
  std::vector<vk::Image> textures_;
  std::vector<SamplerDesc> samplers_;     // of each texture (Texture::sampler)
  std::unique_ptr<MipGenerator> mipGen_;  // a deferred load's, for all its batches
  struct PendingUpload {                  // alive until its submission completed
    explicit PendingUpload(const vk::Context& ctx) : timer(ctx, 1) {}
    std::vector<uint32_t> batch;
    MipViews views;
    vk::GpuTimer timer;
    const vk::Submission* submission = nullptr;  // the ring's
    std::chrono::steady_clock::time_point start;
  };
  std::unique_ptr<PendingUpload> upload_;  // after textures_: destroyed after the ring, before the images
  std::unique_ptr<ThreadPool> fillPool_;   // writes the batches into the ring
  std::unique_ptr<StagingRing> ring_;      // after upload_: waits for its submissions first
  struct MaterialUpdate {                  // the material buffer rewritten by a copy, alive until done
    vk::Buffer staging;
    std::optional<vk::Submission> submission;
  };
  std::list<MaterialUpdate> materialUpdates_;  // after materials_: waited for first
  Bounds bounds_;
  GpuSceneStats stats_;
};

}  // namespace rtr::render
