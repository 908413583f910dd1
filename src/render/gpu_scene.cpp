#include "render/gpu_scene.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstdlib>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <functional>
#include <future>
#include <optional>

#include <glm/gtc/matrix_inverse.hpp>
#include <mutex>

#include "cluster.h"
#include "render/cull.hpp"
#include "render/mesh_records.hpp"
#include "render/staging_ring.hpp"
#include "render/startup.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "core/parallel.hpp"
#include "vk/check.hpp"
#include "vk/commands.hpp"
#include "vk/context.hpp"
#include "vk/pipeline_cache.hpp"

namespace rtr::render {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

}  // namespace

// The geometry's buffers, in uploadGeometry's order (its targets) and geometryBuffers()'.
constexpr const char* kGeometryNames[] = {"positions",  "normals",        "texcoords",    "indices16", "indices32",
                                          "materials",  "draws",          "instances",    "clusters",  "texcoords1",
                                          "tangents",   "colours",        "cluster lods", "id pages",  "cull instances",
                                          "cull nodes", "cluster entries"};

// Where one mesh's data goes in the scene-wide streams (counts of elements, not bytes).
struct MeshSlot {
  const Mesh* mesh;
  size_t vertex, index;  // first vertex; first index in the 16- or 32-bit stream
  bool index16;
};

// A mesh's draw: its DrawItem, which pipeline, and its clusters' CLUSTER_* flags.
struct MeshDraw {
  DrawItem item;
  DrawKind kind;
  uint32_t flags;
};

// A piece of the geometry writing small enough to spread a single large mesh over all cores: a mesh's
// vertices or indices, a mesh's records or tree nodes, bytes of a buffer copied whole, or the base entries
// of a run of instances.
// Build: a mesh's records made (beside the streams' pieces, before their own writes).
enum class Write : uint8_t { Build, Vertices, Indices, Records, Nodes, Bytes, Entries };
struct WriteTask {
  Write what;
  uint32_t slot;  // mesh slot; mesh; target
  size_t begin, end;
};

// The CPU side of the geometry: where each mesh goes in the streams, and the GPU's draw, instance and
// cluster records.
struct GeometryPlan {
  std::vector<MeshSlot> slots;
  std::vector<shader::GpuDraw> draws;
  std::vector<shader::GpuInstance> instances;
  std::vector<std::optional<MeshDraw>> meshDraw;  // per mesh that has triangles
  std::vector<uint32_t> order;                    // the meshes that get records, the largest first
  std::vector<MeshRecords> records;               // per mesh (none for a mesh not drawn or blended)
  size_t clusters = 0, nodes = 0;                 // records and tree nodes of all meshes
  bool lods = false;                              // some mesh has a hierarchy: a GpuClusterLod per record
  std::vector<uint32_t> idPages;                  // visIdPages(): the instance holding each page's first id
  std::vector<shader::GpuCullInstance> cullInstances;
  std::vector<uint64_t> queues;  // per tree depth: (instance, node) pairs at it
  struct Entries {               // per cull instance: where its base entries ((instance, record) of its level 0) go
    size_t at;
    uint32_t instance, mesh;
  };
  std::vector<Entries> entries;
  size_t baseEntries = 0;
  uint64_t pairs = 0, chunks = 0;  // (instance, cluster) pairs; the culling pass's chunks at most
  size_t vertices = 0, count16 = 0, count32 = 0;
  bool anyTexcoords = false, anyUv1 = false, anyTangents = false, anyColors = false;  // glTF's streams
};

namespace {

shader::GpuInstance gpuInstance(const glm::mat4& t, uint32_t draw) {
  // The identity stays exact (existing scenes' images do not move by a rounding).
  const glm::mat3 n = t == glm::mat4(1.0f) ? glm::mat3(1.0f) : glm::inverseTranspose(glm::mat3(t));
  return {t, glm::vec4(n[0], 0.0f), glm::vec4(n[1], 0.0f), glm::vec4(n[2], 0.0f),
          glm::uvec4(draw, mirrored(t) ? INSTANCE_MIRRORED : 0u, 0u, 0u)};
}

}  // namespace

GpuScene::GpuScene(const vk::Context& ctx, const Scene& scene, MipMode mipMode, const LoadProgress& progress,
                   GeometryUpload upload, TextureLoad textureLoad, TextureCache* cache, size_t uploadBudget,
                   size_t geometrySlotBytes)
    : ctx_(ctx), mipMode_(mipMode), progress_(progress), uploadBudget_(uploadBudget), cache_(cache) {
  bounds_ = scene.bounds();
  if (cache_) {  // a chain is the mip mode's on this device and driver (blits and shaders run by it)
    const VkPhysicalDeviceProperties& p = ctx.properties();
    char id[64];
    std::snprintf(id, sizeof id, "%08x:%08x:%08x:", p.vendorID, p.deviceID, p.driverVersion);
    cacheVariant_ = std::string("gpu ") + id;
    for (uint8_t b : p.pipelineCacheUUID) std::snprintf(id, sizeof id, "%02x", b), cacheVariant_ += id;
    cacheVariant_ += std::string("; mips ") + enumName(mipMode) + " " + std::to_string(kMipChainVersion);
  }
  std::future<void> decodeBeside;  // a waited-for load's decode, on a thread of its own beside the geometry
  const std::vector<uint32_t> gpuIndex = startTextures(scene, textureLoad, decodeBeside);
  const auto t = Clock::now();
  const GeometryUpload path = upload == GeometryUpload::Auto ? GeometryUpload::Direct : upload;
  // A staged upload's ring (host memory the driver allocates and pins) is made while the geometry is planned.
  std::future<std::unique_ptr<StagingRing>> ring;
  if (path == GeometryUpload::Staged)
    ring = std::async(std::launch::async, [&ctx, geometrySlotBytes] {
      auto made =
          std::make_unique<StagingRing>(ctx, geometrySlotBytes, kGeometrySlots, kGeometryRingMemory, "geometry staging ring");
      made->allocate();
      return made;
    });
  GeometryPlan plan = planGeometry(scene);
  stats_.geometryPlanMs = msSince(t);
  std::vector<shader::GpuMaterial> materials = gpuMaterials(scene, gpuIndex);
  const SceneKinds kinds = sceneKinds(scene);
  materialExtras_ = kinds.materialExtras;
  identityInstances_ = kinds.identityInstances;
  if (decoding_.valid()) {  // until the textures are in: the factors alone (NO_TEXTURE everywhere)
    texturedMaterials_ = materials;
    for (shader::GpuMaterial& g : materials)
      g.textures = glm::uvec4(NO_TEXTURE), g.textures2.x = g.textures2.y = g.textures2.z = NO_TEXTURE;
    shownMaterials_ = materials;
  }
  uploadGeometry(scene, plan, materials, path, geometrySlotBytes, std::move(ring));
  stats_.geometryMs = msSince(t);
  if (decodeBeside.valid()) {
    const auto w = Clock::now();
    decodeBeside.get();  // rethrows the decode's error
    stats_.decodeWaitMs = msSince(w);
  }
  if (!decoding_.valid()) {
    finishTextures();
    std::vector<std::pair<uint32_t, TextureCacheKey>> misses;
    for (uint32_t i = 0; i < storeKeys_.size(); ++i)
      if (storeKeys_[i]) misses.emplace_back(i, std::move(*storeKeys_[i]));
    storeInCache(std::move(misses), true);
    in_.assign(textures_.size(), 1), texturesIn_ = textures_.size(), ready_ = true;
  }
}

// Geometry: one stream per attribute for all meshes, each mesh once however many instances draw it;
// indices 16-bit where the mesh has <= 65536 vertices. One DrawItem per mesh (two if some of its
// instances are mirrored), drawn instanced over its range of the instance buffer.
GeometryPlan GpuScene::planGeometry(const Scene& scene) {
  GeometryPlan p;
  auto any = [&](auto has) {
    return std::any_of(scene.meshes.begin(), scene.meshes.end(), [&](const Mesh& m) { return !m.indices.empty() && has(m); });
  };
  p.anyTexcoords = any([](const Mesh& m) { return !m.texcoords.empty(); });
  p.anyUv1 = any([](const Mesh& m) { return !m.texcoords1.empty(); });
  p.anyTangents = any([](const Mesh& m) { return !m.tangents.empty(); });
  p.anyColors = any([](const Mesh& m) { return !m.colors.empty(); });
  p.meshDraw.resize(scene.meshes.size());
  for (size_t mi = 0; mi < scene.meshes.size(); ++mi) {
    const Mesh& m = scene.meshes[mi];
    if (m.indices.empty()) continue;
    const Material& mat = scene.materials.at(m.material);
    const bool index16 = m.positions.size() <= 65536;
    DrawItem d;
    d.material = m.material;
    d.indexCount = uint32_t(m.indices.size());
    d.primitives = uint32_t((m.indices.size() + m.lod.indices.size()) / 3);
    d.vertexOffset = int32_t(p.vertices);
    d.indexType = index16 ? VK_INDEX_TYPE_UINT16 : VK_INDEX_TYPE_UINT32;
    d.firstIndex = uint32_t(index16 ? p.count16 : p.count32);
    p.slots.push_back({&m, p.vertices, d.firstIndex, index16});
    (index16 ? p.count16 : p.count32) += m.indices.size() + m.lod.indices.size();  // the hierarchy's after
    stats_.meshes16 += index16;
    p.vertices += m.positions.size();
    const bool textured = !m.texcoords.empty();
    // Two-sided materials go to the alpha-tested pipeline, which does not cull (with no mask texture
    // the alpha is 1 and nothing is discarded): clusterFlags says double-sided.
    const uint32_t flags = clusterFlags(m, mat);
    const DrawKind kind = !textured ? DrawKind::Untextured : flags ? DrawKind::AlphaMasked : DrawKind::Opaque;
    d.id = uint32_t(p.draws.size());
    p.draws.push_back({d.material, d.firstIndex, uint32_t(d.vertexOffset),
                       (index16 ? DRAW_INDEX16 : 0u) | (textured ? DRAW_TEXTURED : 0u) | (m.colors.empty() ? 0u : DRAW_COLORS) |
                           (m.tangents.empty() ? 0u : DRAW_TANGENTS) | (m.texcoords1.empty() ? 0u : DRAW_UV1)});
    p.meshDraw[mi] = MeshDraw{d, kind, flags};
    ++stats_.meshes;
    stats_.triangles += m.triangleCount();
  }
  p.lods = std::any_of(scene.meshes.begin(), scene.meshes.end(), [](const Mesh& m) { return m.lod.levels > 0; });
  // Each mesh's records are made on all cores, the largest first (uploadGeometry), then placed.
  for (uint32_t mi = 0; mi < scene.meshes.size(); ++mi)
    if (p.meshDraw[mi] && !scene.materials.at(scene.meshes[mi].material).blended())
      p.order.push_back(mi);  // else: transparency pass
  auto size = [&](uint32_t mi) { return scene.meshes[mi].indices.size() + scene.meshes[mi].lod.indices.size(); };
  std::stable_sort(p.order.begin(), p.order.end(), [&](uint32_t a, uint32_t b) { return size(a) > size(b); });
  p.records.resize(scene.meshes.size());
  stats_.vertices = uint32_t(p.vertices);
  p.count16 += p.count16 % 2;  // keep the buffer size a multiple of 4
  return p;
}

// Once every mesh's records are made: numbered mesh by mesh, each instance's culling record and draw,
// the visibility ids.
void GpuScene::placeRecords(const Scene& scene, GeometryPlan& p) {
  const std::vector<Instance> instances = gpuInstances(scene);
  std::vector<uint32_t> order = p.order;
  std::sort(order.begin(), order.end());
  for (uint32_t mi : order) {  // numbered mesh by mesh in the scene's order
    MeshRecords& r = p.records[mi];
    r.first = uint32_t(p.clusters), r.firstLevel = uint32_t(p.nodes);
    p.clusters += r.count, p.nodes += r.nodes.size();
  }
  Bounds box;  // of the draw being extended
  uint64_t slots = 0, chunks = 0;
  for (uint32_t i = 0; i < instances.size(); ++i) {
    const Instance& in = instances[i];
    const Mesh& m = scene.meshes[in.mesh];
    const MeshDraw& md = *p.meshDraw[in.mesh];
    const bool flip = mirrored(in.transform);
    p.instances.push_back(gpuInstance(in.transform, md.item.id));
    // The identity keeps the box exact (the nearest-first order of existing scenes unchanged).
    const bool identity = in.transform == glm::mat4(1.0f);
    const Bounds b = identity ? m.bounds : transformed(m.bounds, in.transform);
    if (const Material& mat = scene.materials.at(m.material); mat.blended()) {
      BlendDraw bd{md.item, !m.texcoords.empty(), (mat.flags & kMaterialDoubleSided) != 0};
      bd.item.firstInstance = i, bd.item.mirrored = flip, bd.item.center = b.empty() ? glm::vec3(0.0f) : b.center();
      blendDraws_.push_back(bd);
      continue;
    }
    // Its culling record: the mesh's spheres placed (a sphere holding the placed ones), how to place the
    // records, and its history slots.
    const MeshRecords& r = p.records[in.mesh];
    const std::pair<float, bool> st = largestStretch(in.transform);  // no structured binding: clang 14 lambdas
    const float stretch = st.first;
    const bool similarity = st.second;
    auto place = [&](glm::vec4 s) {
      return identity ? s : glm::vec4(glm::vec3(in.transform * glm::vec4(glm::vec3(s), 1.0f)), s.w * stretch * (1.0f + 1e-5f));
    };
    p.cullInstances.push_back({place(r.sphere), place(r.lodSphere),
                               glm::uvec4(r.firstLevel, r.levels, i, uint32_t(slots - r.first)),
                               glm::vec4(identity ? 1.0f : stretch, similarity ? 1.0f : 0.0f, identity ? 1.0f : 0.0f, 0.0f)});
    p.entries.push_back({p.baseEntries, i, in.mesh});
    p.baseEntries += r.level0;
    slots += r.count;
    chunks += r.leaves;
    if (p.queues.size() < r.depths.size()) p.queues.resize(r.depths.size(), 0);
    for (size_t d = 0; d < r.depths.size(); ++d) p.queues[d] += r.depths[d];
    std::vector<DrawItem>& list = draws_[size_t(md.kind)];
    if (list.empty() || list.back().id != md.item.id || list.back().mirrored != flip) {
      list.push_back(md.item);
      list.back().firstInstance = i, list.back().instanceCount = 0, list.back().mirrored = flip;
      box = {};
    }
    ++list.back().instanceCount;
    box.extend(b);
    if (!box.empty()) list.back().center = box.center();
  }
  p.pairs = slots, p.chunks = chunks;
  // Visibility ids (frame.h): each drawn instance its own range, as long as its draw's primitives, in order.
  uint64_t ids = 0;
  firstIds_.clear();
  for (uint32_t i = 0; i < instances.size(); ++i) {
    const Mesh& m = scene.meshes[instances[i].mesh];
    firstIds_.push_back(ids);
    p.instances[i].info.z = uint32_t(ids);
    if (!scene.materials.at(m.material).blended()) ids += p.meshDraw[instances[i].mesh]->item.primitives;
  }
  visIdCount_ = ids;
  // Pages of 2^shift ids, at most 2^16 + 1 of them: page k's entry is the last instance whose range
  // starts at or before k << shift, so the instance of id lies between the entries of id's page and the next.
  idPageShift_ = uint32_t(std::max(6, int(std::bit_width(std::max<uint64_t>(ids, 1))) - 16));
  if (ids <= kMaxVisIds)
    for (uint64_t page = 0, i = 0; page <= ((std::max<uint64_t>(ids, 1) - 1) >> idPageShift_) + 1; ++page) {
      while (i + 1 < firstIds_.size() && firstIds_[i + 1] <= page << idPageShift_) ++i;
      p.idPages.push_back(uint32_t(i));
    }
  if (p.idPages.empty()) p.idPages.push_back(0);
  stats_.instances = uint32_t(instances.size());
}

std::vector<shader::GpuMaterial> GpuScene::gpuMaterials(const Scene& scene, const std::vector<uint32_t>& gpuIndex) const {
  std::vector<shader::GpuMaterial> materials;
  for (const Material& m : scene.materials) {
    shader::GpuMaterial g{};
    // glTF factors only for glTF materials: OBJ/course ones keep opacity 1 and the cutoff 0.5.
    const bool gltf = m.flags & kMaterialGltf;
    g.baseColor = glm::vec4(m.baseColor, gltf ? m.opacity : 1.0f);
    g.emissive = glm::vec4(m.emissive, m.normalScale);
    g.roughMetal = glm::vec4(m.roughness, m.metalness, gltf ? m.alphaCutoff : 0.5f, m.occlusionStrength);
    for (uint32_t s = 0; s < kTextureSlotCount; ++s) {
      const UvTransform& u = m.uv[s];
      // KHR_texture_transform: offset + R(rotation) (scale * uv), R turning counter-clockwise in uv space.
      const float c = std::cos(u.rotation), sn = std::sin(u.rotation);
      g.uvTransform[2 * s] = u.identity() ? glm::vec4(1, 0, 0, float(u.texCoord))
                                          : glm::vec4(c * u.scale.x, sn * u.scale.y, u.offset.x, float(u.texCoord));
      g.uvTransform[2 * s + 1] = u.identity() ? glm::vec4(0, 1, 0, 0) : glm::vec4(-sn * u.scale.x, c * u.scale.y, u.offset.y, 0);
    }
    auto tex = [&](TextureSlot s) {
      uint32_t t = m.texture(s);
      return t == kNoTexture ? NO_TEXTURE : gpuIndex[t];
    };
    g.textures = glm::uvec4(tex(TextureSlot::BaseColor), tex(TextureSlot::Roughness), tex(TextureSlot::Metalness),
                            tex(TextureSlot::AlphaMask));
    const uint32_t mask = m.texture(TextureSlot::AlphaMask);
    const uint32_t flags = (m.flags & kMaterialUnlit ? MATERIAL_UNLIT : 0u) | (gltf ? MATERIAL_GGX : 0u) |
                           (mask != kNoTexture && scene.textures.at(mask).channels == 1 ? MATERIAL_MASK_RED : 0u);
    g.textures2 = glm::uvec4(tex(TextureSlot::Emissive), gltf ? tex(TextureSlot::Occlusion) : NO_TEXTURE,
                             gltf ? tex(TextureSlot::NormalMap) : NO_TEXTURE, flags);
    materials.push_back(g);
  }
  if (materials.empty()) materials.push_back({});
  return materials;
}

// Each buffer is device-local. Direct: the host writes it in place where the device lets it map such
// memory (every CPU device, a GPU with a large BAR), on all cores, every byte crossing the bus as a CPU
// store. Staged (and any buffer that is not mappable): the same pieces are written on all cores into a
// ring of host staging slots, a batch of pieces a slot, and the GPU copies each slot into place (DMA)
// while the next ones are written (docs/startup.md, "Geometry upload").
void GpuScene::uploadGeometry(const Scene& scene, GeometryPlan& plan, const std::vector<shader::GpuMaterial>& materials,
                              GeometryUpload upload, size_t slotBytes, std::future<std::unique_ptr<StagingRing>> ringMade) {
  struct Target {
    vk::Buffer* buffer;
    size_t size;
    const void* data = nullptr;  // records copied whole; null: the streams, written below
    uint8_t* dst = nullptr;      // mapped; null: written through the staging ring
  };
  const size_t vertices = plan.vertices;
  constexpr VkBufferUsageFlags kVertex = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  constexpr VkBufferUsageFlags kIndex = VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  enum : uint32_t {
    kPos,
    kNrm,
    kUv,
    kI16,
    kI32,
    kMat,
    kDraw,
    kInst,
    kCluster,
    kUv1,
    kTan,
    kCol,
    kLod,
    kIds,
    kCullInst,
    kCullNode,
    kBaseEntries,
    kTargets
  };
  auto bytes = [](const auto& v) { return v.size() * sizeof(v[0]); };
  // The streams' buffers first (their sizes are known); the records' once their meshes' are made.
  std::array<Target, kTargets> targets{{{&positions_, vertices * 12},
                                        {&normals_, vertices * 12},
                                        {&texcoords_, plan.anyTexcoords ? vertices * 8 : 0},
                                        {&indices16_, plan.count16 * 2},
                                        {&indices32_, plan.count32 * 4},
                                        {&materials_},
                                        {&drawInfo_},
                                        {&instances_},
                                        {&clusters_},
                                        {&texcoords1_, plan.anyUv1 ? vertices * 8 : 0},
                                        {&tangents_, plan.anyTangents ? vertices * 16 : 0},
                                        {&colors_, plan.anyColors ? vertices * 16 : 0},
                                        {&clusterLods_},
                                        {&visIdPages_},
                                        {&cullInstances_},
                                        {&cullNodes_},
                                        {&baseEntries_}}};
  // glTF's extra streams are read by the shaders from storage buffers (gl_VertexIndex), not bound as
  // vertex streams: OBJ scenes' pipelines stay as they were.
  const std::array<VkBufferUsageFlags, kTargets> usage{kVertex,  kVertex,  kVertex,  kIndex,   kIndex,   kStorage,
                                                       kStorage, kStorage, kStorage, kStorage, kStorage, kStorage,
                                                       kStorage, kStorage, kStorage, kStorage, kStorage};
  // Makes the buffers of the targets sized and not yet made (mapped where direct and the device allows);
  // copied from too where tests read them back.
  constexpr VkBufferUsageFlags kTransfer = VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  const vk::MemoryUse memory = upload == GeometryUpload::Direct ? vk::MemoryUse::DeviceWrite : vk::MemoryUse::Device;
  auto make = [&] {
    for (size_t i = 0; i < kTargets; ++i) {
      Target& tg = targets[i];
      if (tg.size == 0 || tg.buffer->handle()) continue;
      *tg.buffer = vk::Buffer(ctx_, tg.size, usage[i] | kTransfer, memory, kGeometryNames[i]);
      tg.dst = static_cast<uint8_t*>(tg.buffer->mapped());
    }
  };
  auto phase = Clock::now();
  make();
  stats_.geometryBuffersMs = msSince(phase);

  // The bytes of the buffers a piece writes, one range per buffer at most: fn(target, begin, end).
  auto ranges = [&](const WriteTask& t, auto&& fn) {
    auto range = [&](uint32_t k, size_t first, size_t end, size_t size) {
      if (end > first) fn(k, first * size, end * size);
    };
    if (t.what == Write::Bytes) return range(t.slot, t.begin, t.end, 1);
    if (t.what == Write::Entries) {
      const size_t end = t.end < plan.entries.size() ? plan.entries[t.end].at : plan.baseEntries;
      return range(kBaseEntries, plan.entries[t.begin].at, end, sizeof(glm::uvec2));
    }
    if (t.what == Write::Records) {
      const size_t first = plan.records[t.slot].first;
      range(kCluster, first + t.begin, first + t.end, sizeof(shader::GpuCluster));
      if (plan.lods) range(kLod, first + t.begin, first + t.end, sizeof(shader::GpuClusterLod));
      return;
    }
    if (t.what == Write::Nodes) {
      const size_t first = plan.records[t.slot].firstLevel;
      return range(kCullNode, first + t.begin, first + t.end, sizeof(shader::GpuCullNode));
    }
    if (t.what == Write::Build) return;
    const MeshSlot& s = plan.slots[t.slot];
    if (t.what == Write::Indices) return range(s.index16 ? kI16 : kI32, s.index + t.begin, s.index + t.end, s.index16 ? 2 : 4);
    for (auto [k, stride] : {std::pair{kPos, 12}, {kNrm, 12}, {kUv, 8}, {kUv1, 8}, {kTan, 16}, {kCol, 16}})
      if (targets[k].size) range(k, s.vertex + t.begin, s.vertex + t.end, size_t(stride));
  };
  // Where a piece writes byte b of target k: at[k] + (b - from[k]); in place, or in its slot of the ring.
  struct Place {
    std::array<uint8_t*, kTargets> at;
    std::array<size_t, kTargets> from{};
  };

  // Pieces of at most 256 Ki vertices, 1 Mi indices, 64 Ki records, 1 MiB or 1 Mi base entries, written
  // on all cores; an eighth of that through the ring, so that a slot's batch keeps every core busy.
  const bool ringed = std::any_of(targets.begin(), targets.end(), [](const Target& t) { return t.size && !t.dst; });
  const size_t kVertexChunk = size_t(1) << (ringed ? 15 : 18), kIndexChunk = size_t(1) << (ringed ? 17 : 20),
               kRecordChunk = size_t(1) << (ringed ? 13 : 16);
  // The meshes' records are made while the streams are written (the largest mesh's first).
  std::vector<WriteTask> tasks;
  for (uint32_t mi : plan.order) tasks.push_back({Write::Build, mi, 0, 0});
  for (uint32_t s = 0; s < plan.slots.size(); ++s) {
    for (size_t b = 0, n = plan.slots[s].mesh->positions.size(); b < n; b += kVertexChunk)
      tasks.push_back({Write::Vertices, s, b, std::min(n, b + kVertexChunk)});
    for (size_t b = 0, n = plan.slots[s].mesh->indices.size() + plan.slots[s].mesh->lod.indices.size(); b < n; b += kIndexChunk)
      tasks.push_back({Write::Indices, s, b, std::min(n, b + kIndexChunk)});
  }
  auto writePiece = [&](const WriteTask& task, const Place& place) {
    auto to = [&](uint32_t k, size_t byte) { return place.at[k] + (byte - place.from[k]); };
    if (task.what == Write::Bytes) {
      std::memcpy(to(task.slot, task.begin), static_cast<const uint8_t*>(targets[task.slot].data) + task.begin,
                  task.end - task.begin);
      return;
    }
    if (task.what == Write::Entries) {
      for (size_t j = task.begin; j < task.end; ++j) {
        const GeometryPlan::Entries& e = plan.entries[j];
        const MeshRecords& r = plan.records[e.mesh];
        auto* dst = reinterpret_cast<glm::uvec2*>(to(kBaseEntries, e.at * sizeof(glm::uvec2)));
        for (uint32_t k = 0; k < r.level0; ++k) dst[k] = glm::uvec2(e.instance, r.first + k);
      }
      return;
    }
    if (task.what == Write::Records) {  // in the scene-wide numbering
      const MeshRecords& r = plan.records[task.slot];
      const size_t n = task.end - task.begin;
      std::memcpy(to(kCluster, (r.first + task.begin) * sizeof(shader::GpuCluster)), &r.clusters[task.begin],
                  n * sizeof(shader::GpuCluster));
      if (plan.lods)
        std::memcpy(to(kLod, (r.first + task.begin) * sizeof(shader::GpuClusterLod)), &r.lods[task.begin],
                    n * sizeof(shader::GpuClusterLod));
      return;
    }
    if (task.what == Write::Nodes) {  // leaves name records, other nodes their children: both renumbered
      const MeshRecords& r = plan.records[task.slot];
      auto* dst = reinterpret_cast<shader::GpuCullNode*>(to(kCullNode, r.firstLevel * sizeof(shader::GpuCullNode)));
      for (size_t k = 0; k < r.nodes.size(); ++k) {
        shader::GpuCullNode node = r.nodes[k];
        node.first += node.count & CULL_NODE_LEAF ? r.first : r.firstLevel;
        dst[k] = node;
      }
      return;
    }
    const MeshSlot& slot = plan.slots[task.slot];
    const Mesh& m = *slot.mesh;
    const size_t n = task.end - task.begin;
    if (task.what == Write::Indices) {  // the mesh's indices, then its hierarchy's
      const size_t own = m.indices.size();
      for (size_t b = task.begin; b < task.end;) {
        const bool lod = b >= own;
        const uint32_t* src = lod ? &m.lod.indices[b - own] : &m.indices[b];
        const size_t run = std::min(task.end, lod ? task.end : own) - b;
        if (slot.index16) {
          auto* dst = reinterpret_cast<uint16_t*>(to(kI16, (slot.index + b) * 2));
          for (size_t k = 0; k < run; ++k) dst[k] = uint16_t(src[k]);
        } else {
          std::memcpy(to(kI32, (slot.index + b) * 4), src, run * 4);
        }
        b += run;
      }
      return;
    }
    const size_t v = slot.vertex + task.begin;
    std::memcpy(to(kPos, v * 12), &m.positions[task.begin], n * 12);
    // A stream a mesh lacks reads as zeros, so that every stream stays aligned with the positions.
    auto stream = [&](uint32_t k, const auto& src, size_t stride) {
      const size_t have = std::min(n, src.size() > task.begin ? src.size() - task.begin : 0);
      if (have) std::memcpy(to(k, v * stride), &src[task.begin], have * stride);
      if (have < n) std::memset(to(k, (v + have) * stride), 0, (n - have) * stride);
    };
    stream(kNrm, m.normals, 12);
    if (plan.anyTexcoords) stream(kUv, m.texcoords, 8);
    if (plan.anyUv1) stream(kUv1, m.texcoords1, 8);
    if (plan.anyTangents) stream(kTan, m.tangents, 16);
    if (plan.anyColors) stream(kCol, m.colors, 16);
  };
  std::atomic<int64_t> longestBuildUs{0};
  auto write = [&](const WriteTask& task, const Place& place) {
    if (task.what == Write::Build) {
      const auto t = Clock::now();
      // A large mesh's on all cores (beside the streams' writers), in fixed pieces (render/mesh_records.hpp).
      plan.records[task.slot] = buildMeshRecords(scene.meshes[task.slot], plan.meshDraw[task.slot]->flags, plan.lods);
      const int64_t us = int64_t(msSince(t) * 1e3);
      for (int64_t was = longestBuildUs; us > was && !longestBuildUs.compare_exchange_weak(was, us);) {}
      return;
    }
    writePiece(task, place);
  };

  // Runs the tasks on all cores, the records' builds first (as direct's). Where a buffer is not mapped,
  // its bytes go through the ring: the pieces, in order, in batches whose staged bytes fit a slot (at
  // least one piece), batch k (counted over both runs) in slot k % slots, placed before any is written.
  // No thread waits for a batch: a thread takes the next task, waits only where its piece's slot is still
  // read by the copies of the batch before it there, writes, and the thread that writes a batch's last
  // piece submits its copies, which run while the next batches are written.
  std::unique_ptr<StagingRing> ring;                 // made beside the plan (Staged), else where a buffer is not mapped
  std::deque<std::optional<vk::Submission>> copied;  // per batch through the ring: its copies (guarded by copiedMutex)
  std::mutex copiedMutex;
  std::condition_variable copiedChanged;
  std::atomic<int64_t> waitUs{0}, submitUs{0};
  auto run = [&](const std::vector<WriteTask>& tasks) {
    Place direct;
    for (uint32_t k = 0; k < kTargets; ++k) direct.at[k] = targets[k].dst;
    std::vector<Place> places(tasks.size(), direct);
    std::vector<size_t> staged(tasks.size(), 0);  // bytes of a piece in the ring
    for (size_t i = 0; i < tasks.size(); ++i)
      ranges(tasks[i], [&](uint32_t k, size_t b, size_t e) { staged[i] += targets[k].dst ? 0 : e - b + 32; });
    const size_t largest = *std::max_element(staged.begin(), staged.end());
    if (largest == 0) return parallelFor(tasks.size(), 0, [&](size_t i) { write(tasks[i], places[i]); });
    if (!ring && ringMade.valid()) ring = ringMade.get();
    if (ring && largest > ring->slotBytes()) copied.clear(), ring.reset();  // waits for the copies, then larger slots
    if (!ring) {
      ring = std::make_unique<StagingRing>(ctx_, std::max(slotBytes, largest), kGeometrySlots, kGeometryRingMemory,
                                           "geometry staging ring");
      ring->allocate();
    }
    const size_t first = copied.size(), slots = ring->slots();
    std::vector<size_t> batchOf(tasks.size(), SIZE_MAX);
    std::vector<std::vector<size_t>> batches;  // the staged pieces of each batch, in order
    for (size_t i = 0, used = ring->slotBytes(); i < tasks.size(); ++i) {
      if (!staged[i]) continue;
      if (used + staged[i] > ring->slotBytes()) batches.emplace_back(), used = 0;
      used += staged[i];
      batchOf[i] = batches.size() - 1;
      batches.back().push_back(i);
    }
    std::vector<std::array<std::vector<VkBufferCopy>, kTargets>> copies(batches.size());
    for (size_t batch = 0; batch < batches.size(); ++batch) {
      const uint32_t slot = uint32_t((first + batch) % slots);
      // Target by target, each range placed at its byte's alignment (mod 16), right after the one before
      // where it continues it: one copy region a run (lavapipe maps its memory once per region).
      size_t at = ring->offset(slot);
      for (uint32_t target = 0; target < kTargets; ++target)
        for (size_t i : batches[batch])
          ranges(tasks[i], [&](uint32_t k, size_t b, size_t e) {
            if (k != target || targets[k].dst) return;
            std::vector<VkBufferCopy>& c = copies[batch][k];
            if (c.empty() || c.back().dstOffset + c.back().size != b) {
              at = ((at + 15) & ~size_t(15)) + b % 16;
              c.push_back({at, b, 0});
            }
            places[i].at[k] = ring->data(slot) + (at - ring->offset(slot)), places[i].from[k] = b;
            c.back().size += e - b, at += e - b;
          });
    }
    std::vector<std::atomic<size_t>> left(batches.size());  // pieces not yet written
    for (size_t batch = 0; batch < batches.size(); ++batch) left[batch] = batches[batch].size();
    {
      std::lock_guard lock(copiedMutex);
      copied.resize(first + copies.size());
    }
    bool failed = false;  // a piece failed: nobody waits for its batch (guarded by copiedMutex)
    auto waitFor = [&](size_t k) {
      const auto t = Clock::now();
      const vk::Submission* s;
      {
        std::unique_lock lock(copiedMutex);
        copiedChanged.wait(lock, [&] { return copied[k].has_value() || failed; });
        if (!copied[k]) throw Error("geometry upload: an earlier piece failed");
        s = &*copied[k];
      }
      s->wait();
      waitUs += int64_t(msSince(t) * 1e3);
    };
    parallelFor(tasks.size(), 0, [&](size_t i) {
      if (!staged[i]) return write(tasks[i], places[i]);
      const size_t batch = batchOf[i], k = first + batch;
      try {
        if (k >= slots) waitFor(k - slots);
        write(tasks[i], places[i]);
        if (left[batch].fetch_sub(1) != 1) return;
        const auto t = Clock::now();
        std::lock_guard lock(copiedMutex);  // also keeps the queue to one thread
        ring->flush();
        copied[k].emplace(ctx_, [&](VkCommandBuffer cb) {
          for (uint32_t target = 0; target < kTargets; ++target)
            if (!copies[batch][target].empty())
              vkCmdCopyBuffer(cb, ring->buffer(), targets[target].buffer->handle(), uint32_t(copies[batch][target].size()),
                              copies[batch][target].data());
          // Orders the copies before the later ones and the frames' reads, which come in later submissions.
          vk::bufferBarrier(cb, vk::kCopyWrite,
                            vk::kCopyWrite | vk::kVertexInput | vk::kVertexRead | vk::kFragmentRead | vk::kComputeRead);
        });
        copiedChanged.notify_all();
        submitUs += int64_t(msSince(t) * 1e3);
      } catch (...) {
        std::lock_guard lock(copiedMutex);
        failed = true;
        copiedChanged.notify_all();
        throw;
      }
    });
    stats_.geometryCopies += uint32_t(batches.size());
  };
  phase = Clock::now();
  run(tasks);
  stats_.geometryStreamsMs = msSince(phase);

  phase = Clock::now();
  placeRecords(scene, plan);
  // Past 32 bits of (instance, cluster) pairs the compute rasteriser is not used (Renderer).
  clusterCount_ = uint32_t(std::min<uint64_t>(plan.pairs, UINT32_MAX));
  baseClusterCount_ = uint32_t(plan.baseEntries);
  chunkCapacity_ = uint32_t(std::min<uint64_t>(plan.chunks, UINT32_MAX));
  cullQueueCapacity_.clear();
  for (uint64_t n : plan.queues) cullQueueCapacity_.push_back(uint32_t(std::min<uint64_t>(n, UINT32_MAX)));
  cullInstanceCount_ = uint32_t(plan.cullInstances.size());
  targets[kMat] = {&materials_, bytes(materials), materials.data()};
  targets[kDraw] = {&drawInfo_, bytes(plan.draws), plan.draws.data()};
  targets[kInst] = {&instances_, bytes(plan.instances), plan.instances.data()};
  targets[kCluster] = {&clusters_, plan.clusters * sizeof(shader::GpuCluster)};
  targets[kLod] = {&clusterLods_, plan.lods ? plan.clusters * sizeof(shader::GpuClusterLod) : 0};
  targets[kIds] = {&visIdPages_, bytes(plan.idPages), plan.idPages.data()};
  targets[kCullInst] = {&cullInstances_, bytes(plan.cullInstances), plan.cullInstances.data()};
  targets[kCullNode] = {&cullNodes_, plan.nodes * sizeof(shader::GpuCullNode)};
  targets[kBaseEntries] = {&baseEntries_, plan.baseEntries * sizeof(glm::uvec2)};
  make();
  tasks.clear();
  for (uint32_t mi = 0; mi < plan.records.size(); ++mi) {
    for (size_t b = 0, n = plan.records[mi].count; b < n; b += kRecordChunk)
      tasks.push_back({Write::Records, mi, b, std::min(n, b + kRecordChunk)});
    if (!plan.records[mi].nodes.empty()) tasks.push_back({Write::Nodes, mi, 0, plan.records[mi].nodes.size()});
  }
  for (uint32_t t = 0; t < kTargets; ++t)
    for (size_t b = 0; targets[t].data && b < targets[t].size; b += kIndexChunk)
      tasks.push_back({Write::Bytes, t, b, std::min(targets[t].size, b + kIndexChunk)});
  for (size_t j = 0; j < plan.entries.size();) {  // runs of instances holding at least 1 Mi entries (or the rest)
    size_t e = j + 1;
    while (e < plan.entries.size() && plan.entries[e].at - plan.entries[j].at < kIndexChunk) ++e;
    tasks.push_back({Write::Entries, 0, j, e});
    j = e;
  }
  run(tasks);
  for (MeshRecords& r : plan.records) r.clusters.release(0), r.lods.release(0);  // a large one's pages freed on all cores
  stats_.geometryRecordsMs = msSince(phase);
  for (const Target& tg : targets)
    if (tg.size && tg.dst) tg.buffer->flush();
  if (ring) {
    const auto last = Clock::now();
    copied.clear();  // waits for the last copies
    stats_.geometryRingMs = ring->allocationMs(), stats_.geometrySubmitMs = double(submitUs) * 1e-3;
    stats_.geometryWaitMs = double(waitUs) * 1e-3 + msSince(last);
    ring.reset();
  }
  stats_.geometryLongestBuildMs = double(longestBuildUs) * 1e-3;
  stats_.geometryUpload = stats_.geometryCopies ? GeometryUpload::Staged : upload;  // direct: unless a buffer was not mappable
  stats_.geometryBytes = 0;
  for (const Target& tg : targets) stats_.geometryBytes += tg.size;
}

std::vector<std::pair<const char*, const vk::Buffer*>> GpuScene::geometryBuffers() const {
  const vk::Buffer* in[] = {&positions_,   &normals_,    &texcoords_,     &indices16_,  &indices32_,  &materials_,
                            &drawInfo_,    &instances_,  &clusters_,      &texcoords1_, &tangents_,   &colors_,
                            &clusterLods_, &visIdPages_, &cullInstances_, &cullNodes_,  &baseEntries_};
  std::vector<std::pair<const char*, const vk::Buffer*>> out;
  for (size_t i = 0; i < std::size(in); ++i) out.emplace_back(kGeometryNames[i], in[i]);
  return out;
}

std::pair<uint32_t, uint32_t> GpuScene::decodeVisId(uint32_t id) const {
  const auto next = std::upper_bound(firstIds_.begin(), firstIds_.end(), uint64_t(id));
  if (next == firstIds_.begin() || id >= visIdCount_) throw Error("visibility id " + std::to_string(id) + " names no instance");
  const uint32_t instance = uint32_t(next - firstIds_.begin() - 1);
  return {instance, uint32_t(id - firstIds_[instance])};
}

GpuScene::~GpuScene() {
  if (decoding_.valid()) decoding_.wait();  // it writes into this object's staging buffers
  for (auto& f : storing_) f.wait();        // they read this object's read-back buffers
}  // a pending upload and material updates wait for their submissions, before the images and buffers go

float maxAnisotropy(const vk::Context& ctx) {
  VkPhysicalDeviceFeatures features{};
  vkGetPhysicalDeviceFeatures(ctx.physicalDevice(), &features);  // the context enables it where supported
  return features.samplerAnisotropy ? ctx.properties().limits.maxSamplerAnisotropy : 1.0f;
}

vk::Sampler makeSampler(const vk::Context& ctx, const SamplerSettings& settings, const SamplerDesc& desc) {
  VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  const bool nearest = settings.filter == TextureFilter::Nearest;
  si.magFilter = nearest || desc.nearestMag ? VK_FILTER_NEAREST : VK_FILTER_LINEAR;
  si.minFilter = nearest || desc.nearestMin ? VK_FILTER_NEAREST : VK_FILTER_LINEAR;
  si.mipmapMode = settings.filter == TextureFilter::Trilinear && !desc.nearestMip ? VK_SAMPLER_MIPMAP_MODE_LINEAR
                                                                                  : VK_SAMPLER_MIPMAP_MODE_NEAREST;
  auto wrap = [](Wrap w) {
    return w == Wrap::ClampToEdge      ? VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE
           : w == Wrap::MirroredRepeat ? VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT
                                       : VK_SAMPLER_ADDRESS_MODE_REPEAT;
  };
  si.addressModeU = wrap(desc.wrapU);
  si.addressModeV = si.addressModeW = wrap(desc.wrapV);
  si.maxLod = VK_LOD_CLAMP_NONE;
  // Off by default: the mip-level view must show what plain trilinear filtering picks.
  const float anisotropy = std::clamp(settings.anisotropy, 1.0f, maxAnisotropy(ctx));
  si.anisotropyEnable = anisotropy > 1.0f;
  si.maxAnisotropy = anisotropy;
  VkSampler raw;
  VK_CHECK(vkCreateSampler(ctx.device(), &si, nullptr, &raw));
  return vk::Sampler(ctx.device(), raw);
}

}  // namespace rtr::render
