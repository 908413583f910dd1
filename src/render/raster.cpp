#include "render/raster.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>

#include "core/env.hpp"
#include "raster.h"
#include "vk/commands.hpp"
#include "vk/context.hpp"

namespace rtr::render {

bool ComputeRaster::supported(const vk::Context& ctx) {
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f12};
  vkGetPhysicalDeviceFeatures2(ctx.physicalDevice(), &f2);  // the context enables them where all are supported
  return f2.features.shaderInt64 && f2.features.fragmentStoresAndAtomics && f12.shaderBufferInt64Atomics;
}

namespace {

// RTR_RASTER_MEASURE=no-atomics|setup: raster.comp without its per-pixel atomics or its pixel loop, so that
// a --timings run splits "raster" into fetch and setup, edge tests and atomics (docs/raster.md, "What bounds
// each pass"). Measuring only: the ids are then wrong, so it says so.
std::vector<vk::SpecializationConstant> withMeasure(std::vector<vk::SpecializationConstant> constants) {
  const char* v = std::getenv("RTR_RASTER_MEASURE");
  if (!v || !*v) return constants;
  const std::string mode = v;
  if (mode != "no-atomics" && mode != "setup")
    throw std::runtime_error("RTR_RASTER_MEASURE=" + mode + ": expected no-atomics or setup");
  std::fprintf(stderr, "RTR_RASTER_MEASURE=%s: the raster pass writes no ids (measuring only)\n", v);
  constants.push_back({2, mode == "setup" ? RASTER_MEASURE_SETUP : RASTER_MEASURE_NO_ATOMICS});
  return constants;
}

// RTR_RASTER_MEDIUM=T: raster.comp's medium triangles are those whose box is over T pixels (its kMediumFrom,
// RASTER_MEDIUM_FROM by default; 0: none, each small triangle drawn by its own thread as before), and
// RTR_RASTER_MEDIUM_LANES=16|32: those of up to RASTER_MEDIUM_NARROW_AREA pixels drawn by 16 threads (the
// default) or, like the larger ones, by 32 (its kMediumNarrow 0); for measuring (docs/raster.md, "Medium
// triangles"). The same ids whatever they are.
std::vector<vk::SpecializationConstant> withMedium(std::vector<vk::SpecializationConstant> constants) {
  if (const auto t = envNumber("RTR_RASTER_MEDIUM", 0, RASTER_SHARED_AREA - 1, "a number of pixels (0: no medium list)"))
    constants.push_back({3, *t == 0 ? RASTER_SHARED_AREA : *t});
  if (const char* lanes = std::getenv("RTR_RASTER_MEDIUM_LANES"); lanes && *lanes) {
    if (std::string(lanes) != "16" && std::string(lanes) != "32")
      throw std::runtime_error(std::string("RTR_RASTER_MEDIUM_LANES=") + lanes + ": expected 16 or 32");
    if (std::string(lanes) == "32") constants.push_back({4, 0u});
  }
  return constants;
}

}  // namespace

ComputeRaster::Pipelines ComputeRaster::makePipelines(const vk::Context& ctx, const SceneKinds& kinds) {
  const vk::LayoutOptions push{.pushDescriptorSets = {0}};
  vk::LayoutOptions options = push;
  options.runtimeArrayCounts[{1, 0}] = std::max(1u, kinds.textures);
  // The alpha test in compute only where some material is masked (raster_tri.glsl's kAlphaMask).
  const std::vector<vk::SpecializationConstant> constants{{0, RASTER_SHARED_AREA},
                                                          {1, kinds.draws[size_t(DrawKind::AlphaMasked)]}};
  Pipelines p;
  vk::inParallel({
      [&] { p.clear = vk::makeComputePipeline(ctx, vk::loadShader("raster_clear.comp"), push); },
      [&] {
        p.raster = vk::makeComputePipeline(ctx, vk::loadShader("raster.comp"), options, withMedium(withMeasure(constants)));
      },
      [&] { p.clip = vk::makeComputePipeline(ctx, vk::loadShader("raster_clip.comp"), options, constants); },
      [&] { p.large = vk::makeComputePipeline(ctx, vk::loadShader("raster_large.comp"), options, constants); },
      [&] {
        vk::GraphicsDesc d;
        d.modules = {vk::loadShader("raster_hw.vert"), vk::loadShader("raster_hw.frag")};
        d.cullMode = VK_CULL_MODE_NONE;  // the fragment stage culls by the cluster's flags
        d.depthTest = d.depthWrite = false;
        p.hardware = vk::makeGraphicsPipeline(ctx, d, options);
      },
  });
  return p;
}

ComputeRaster::ComputeRaster(const vk::Context& ctx, const GpuScene& scene, uint32_t framesInFlight,
                             std::optional<Pipelines> made)
    : ctx_(ctx),
      scene_(scene),
      culled_(framesInFlight, false),
      twoPhase_(framesInFlight, false),
      counted_(framesInFlight, false) {
  // RTR_CLEAR_IN_SHADE=0: the full clear every frame, as before the fold (A/B on a GPU; docs/raster.md).
  foldClear_ = envNumber("RTR_CLEAR_IN_SHADE", 0, 1, "0 (a full clear every frame) or 1").value_or(1) != 0;
  Pipelines p = made ? std::move(*made) : makePipelines(ctx, scene.kinds());
  clear_ = std::move(p.clear), raster_ = std::move(p.raster), clip_ = std::move(p.clip), large_ = std::move(p.large);
  hardware_ = std::move(p.hardware);
  // Written by the renderer (Renderer::writeTextures).
  for (size_t i = 0; i < textured().size(); ++i)
    if (textured()[i]->layout.setCount() > 1) textures_[i] = vk::DescriptorSets(ctx, textured()[i]->layout, 1);
  // Every triangle at most once in the hand-off list, after its VkDrawIndirectCommand.
  uint64_t triangles = 0;
  for (size_t k = 0; k < kDrawKindCount; ++k)
    for (const DrawItem& di : scene.draws(DrawKind(k))) triangles += uint64_t(di.primitives) * di.instanceCount;
  handOffCapacity_ = uint32_t(std::clamp<uint64_t>(triangles, 1, RASTER_HANDOFF_CAPACITY));
  // Medium triangles' records: as many as the scene has triangles, at most RASTER_MEDIUM_TRIANGLES (28 MiB);
  // RTR_RASTER_MEDIUM_CAPACITY=N sets it (testing the list's overflow, measuring).
  mediumCapacity_ = envNumber("RTR_RASTER_MEDIUM_CAPACITY", 1, 1u << 22, "a number of records")
                        .value_or(uint32_t(std::clamp<uint64_t>(triangles, 1, RASTER_MEDIUM_TRIANGLES)));
  hwList_ =
      vk::Buffer(ctx, sizeof(VkDrawIndirectCommand) + 4 * std::clamp<uint64_t>(triangles, 1, RASTER_HANDOFF_CAPACITY),
                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                 vk::MemoryUse::Device, "raster hand-off");
  clipList_ = vk::Buffer(ctx, 32 + 4 * VkDeviceSize(RASTER_CLIP_CAPACITY),
                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                             VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                         vk::MemoryUse::Device, "raster clipping list");
  largeList_ =
      vk::Buffer(ctx, 48 + 8 * VkDeviceSize(RASTER_LARGE_CAPACITY),
                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                 vk::MemoryUse::Device, "raster tiles");
  largeTris_ = vk::Buffer(ctx, sizeof(shader::RasterLargeTri) * VkDeviceSize(RASTER_LARGE_TRIANGLES + mediumCapacity_),
                          VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUse::Device, "raster large triangles");
  cullReadback_ = vk::Buffer(ctx, 2 * sizeof(shader::CullCounts) * framesInFlight, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                             vk::MemoryUse::Readback, "cull counts read-back");
  handOffReadback_ = vk::Buffer(ctx, kReadbackSize * framesInFlight, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback,
                                "hand-off count read-back");
}

std::vector<std::pair<const vk::PipelineLayout*, VkDescriptorSet>> ComputeRaster::textureSets() const {
  std::vector<std::pair<const vk::PipelineLayout*, VkDescriptorSet>> sets;
  for (size_t i = 0; i < textured().size(); ++i)
    if (textured()[i]->layout.setCount() > 1) sets.emplace_back(&textured()[i]->layout, textures_[i].get(1));
  return sets;
}

uint32_t ComputeRaster::handOffTriangles(uint32_t frame) const {
  handOffReadback_.invalidate();
  uint32_t vertices = 0;
  std::memcpy(&vertices, static_cast<const char*>(handOffReadback_.mapped()) + kReadbackSize * frame, 4);
  return vertices / 3;
}

uint32_t ComputeRaster::clippedTriangles(uint32_t frame) const {
  handOffReadback_.invalidate();
  uint32_t clipped = 0;
  std::memcpy(&clipped, static_cast<const char*>(handOffReadback_.mapped()) + kReadbackSize * frame + 4, 4);
  return std::min(clipped, RASTER_CLIP_CAPACITY);  // the count goes on past the list; those went to the hardware
}

ComputeRaster::MediumCounts ComputeRaster::mediumTriangles(uint32_t frame) const {
  handOffReadback_.invalidate();
  uint32_t c[4] = {};  // LargeList's mediumFound and mediumStored (raster_fetch.glsl): 16 lanes, 32 lanes each
  std::memcpy(c, static_cast<const char*>(handOffReadback_.mapped()) + kReadbackSize * frame + 8, sizeof c);
  return {c[0], c[1], c[0] - std::min(c[0], c[2]) + c[1] - std::min(c[1], c[3])};
}

std::optional<ComputeRaster::CullStats> ComputeRaster::cullStats(uint32_t frame) const {
  if (!culled_.at(frame)) return std::nullopt;
  cullReadback_.invalidate();
  shader::CullCounts c[2];
  std::memcpy(c, static_cast<const char*>(cullReadback_.mapped()) + sizeof c * frame, sizeof c);
  const uint32_t early = twoPhase_.at(frame) ? c[0].listed : 0, earlyTriangles = twoPhase_.at(frame) ? c[0].triangles : 0;
  CullStats s{scene_.clusterCount(), early,          c[1].listed,    c[1].culled[0],
              c[1].culled[1],        c[1].culled[2], c[1].culled[3], earlyTriangles + c[1].triangles};
  s.tested = (twoPhase_.at(frame) ? c[0].tested : 0) + c[1].tested;
  s.instancesCulled = c[1].instancesCulled;
  s.nodes = (twoPhase_.at(frame) ? c[0].nodes : 0) + c[1].nodes;
  return s;
}

void ComputeRaster::resize(VkExtent2D extent) {
  if (extent.width == extent_.width && extent.height == extent_.height) return;
  vis_ = vk::Buffer(ctx_, VkDeviceSize(extent.width) * extent.height * 8,
                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUse::Device,
                    "visibility (64-bit)");
  pyramid_.reset();
  extent_ = extent;
  visClear_ = false;  // a new buffer: its contents undefined
}

void ComputeRaster::record(VkCommandBuffer cb, const vk::UploadArena::Slice& uniforms, vk::GpuTimer& timer, uint32_t frame,
                           const CullCamera& camera, Culling cull, bool clip, bool counters) {
  // A scene may lack one index width or texcoords: any storage buffer fills that binding (nothing reads it).
  const VkBuffer i16 = scene_.indices16() ? scene_.indices16() : scene_.indices32();
  const VkBuffer i32 = scene_.indices32() ? scene_.indices32() : scene_.indices16();
  const VkBuffer uv = scene_.texcoords() ? scene_.texcoords() : scene_.positions();
  // Level 0 only (the first baseClusterCount() records) unless a cut is chosen.
  const bool lod = scene_.clusterLods() && camera.lodThreshold > 0.0f && !camera.orthographic;
  const uint32_t clusterCount = lod ? scene_.clusterCount() : scene_.baseClusterCount();
  if (cull == Culling::Auto) cull = lod ? Culling::Frustum : Culling::Off;
  const bool twoPhase = cull == Culling::TwoPhase && clusterCount > 0;
  const bool culling = (cull != Culling::Off || lod) && clusterCount > 0;
  if (culling && !culler_) culler_.emplace(ctx_, scene_.clusterCount(), scene_.chunkCapacity(), scene_.cullQueueCapacity());
  if (twoPhase && !pyramid_) pyramid_.emplace(ctx_, extent_);
  culled_.at(frame) = culling;
  twoPhase_.at(frame) = twoPhase;
  counted_.at(frame) = counters;
  const VkBuffer lods = lod ? scene_.clusterLods() : VK_NULL_HANDLE;
  auto bind = [&](const vk::Pipeline& p, bool fromList = false) {
    p.bind(cb);
    vk::DescriptorWriter w(ctx_, p.layout, 0, VK_NULL_HANDLE);
    for (const vk::ReflectedBinding& b : p.layout.interface().bindings) {
      if (b.set != 0) continue;
      const VkBuffer list = culling ? culler_->visible() : scene_.baseEntries();
      const VkBuffer counts = culler_ ? culler_->counts() : scene_.clusters();  // not read without culling
      const VkBuffer buffers[] = {uniforms.buffer,
                                  scene_.clusters(),
                                  scene_.drawInfo(),
                                  scene_.positions(),
                                  i32,
                                  i16,
                                  vis_.handle(),
                                  hwList_.handle(),
                                  scene_.materials(),
                                  uv,
                                  largeList_.handle(),
                                  list,
                                  counts,
                                  scene_.instances(),
                                  largeTris_.handle(),
                                  clipList_.handle()};
      if (b.binding == 0) w.buffer(0, uniforms.buffer, uniforms.offset, sizeof(shader::FrameUniforms));
      else w.buffer(b.binding, buffers[b.binding]);
    }
    w.push(cb, p);
    for (size_t i = 0; i < textured().size(); ++i)
      if (&p == textured()[i] && p.layout.setCount() > 1) p.bindSet(cb, 1, textures_[i].get(1));
    p.push(cb,
           shader::RasterPush{extent_.width, extent_.height, clusterCount, fromList, handOffCapacity_, clip, mediumCapacity_, 0});
  };
  // The passes that read the rasteriser's buffers after it: shading and the hardware rasteriser's draw.
  constexpr vk::BufferUse kReaders = vk::kComputeReadWrite | vk::kFragmentReadWrite | vk::kVertexReadWrite | vk::kIndirectRead;
  // The previous frame's readers of both buffers (shading, the indirect draw) before they are cleared.
  vk::bufferBarrier(cb, kReaders | vk::kCopyRead, vk::kComputeWrite);
  // Every pixel, or where the shading pass of the frame before cleared them (shadingCleared), one workgroup:
  // its threads rewrite the first pixels' RASTER_CLEAR and its thread 0 resets the lists.
  bind(clear_);
  clear_.dispatch(cb, visClear_ ? 1 : extent_.width * extent_.height);
  visClear_ = false;  // this frame's ids, until its shading pass clears them
  timer.mark(cb, "clear");
  vk::bufferBarrier(cb, vk::kComputeWrite, vk::kComputeReadWrite);
  const VkDeviceSize countsSize = sizeof(shader::CullCounts);
  const VkBufferCopy toReadback[2] = {{0, 2 * countsSize * frame, countsSize}, {0, (2 * frame + 1) * countsSize, countsSize}};
  // Both rasteriser passes over the clusters: all of them, or (culling) the culler's list, indirectly.
  auto rasterise = [&](const char* name, const char* clipName, const char* largeName) {
    bind(raster_, culling);
    if (culling) {
      vkCmdDispatchIndirect(cb, culler_->counts(), 0);
    } else {
      // Workgroup counts per dimension are limited (65535 on many devices): clusters over x, then y.
      const uint32_t maxX = std::min(ctx_.properties().limits.maxComputeWorkGroupCount[0], 65535u);
      const uint32_t x = std::min(clusterCount, maxX);
      vkCmdDispatch(cb, x, (clusterCount + x - 1) / x, 1);
    }
    timer.mark(cb, name);
    if (clip) {  // its list's entries and workgroup count are raster's
      vk::bufferBarrier(cb, vk::kComputeWrite, vk::kComputeReadWrite | vk::kIndirectRead);
      bind(clip_);
      vkCmdDispatchIndirect(cb, clipList_.handle(), 0);
      timer.mark(cb, clipName);
    }
    vk::bufferBarrier(cb, vk::kComputeWrite, vk::kComputeReadWrite);
    bind(large_);
    vkCmdDispatch(cb, RASTER_LARGE_GROUPS, 1, 1);
    timer.mark(cb, largeName);
  };
  if (culling && !twoPhase) {  // one pass: frustum and cones (Culling::Frustum), the level-of-detail cut
    const bool tests = cull == Culling::Frustum;
    culler_->record(cb, scene_.clusters(), clusterCount, camera, nullptr, {tests, tests, false, true}, CullPhase::Single, lods,
                    scene_.cullInstances(), scene_.cullInstanceCount(), scene_.cullNodes(), scene_.instances());
    if (counters) {
      vkCmdCopyBuffer(cb, culler_->counts(), cullReadback_.handle(), 1, &toReadback[1]);
      vk::bufferBarrier(cb, vk::kCopyWrite, vk::kHostRead);
    }
    timer.mark(cb, "cull");
  }
  if (twoPhase) {
    culler_->record(cb, scene_.clusters(), clusterCount, camera, nullptr, {}, CullPhase::Early, lods, scene_.cullInstances(),
                    scene_.cullInstanceCount(), scene_.cullNodes(), scene_.instances());
    if (counters) vkCmdCopyBuffer(cb, culler_->counts(), cullReadback_.handle(), 1, &toReadback[0]);
    timer.mark(cb, "cull early");
    rasterise("raster early", "raster clip early", "raster large early");
    // The pyramid reads the depth drawn so far; the late phase's tile pass starts after the early tiles.
    vk::bufferBarrier(cb, vk::kComputeWrite, vk::kComputeReadWrite | vk::kCopyRead);
    const VkBufferCopy firstLate[2] = {{0, 4, 4}, {16, 24, 8}};  // largeCount -> largeFirst, mediumFound -> mediumFirst
    vkCmdCopyBuffer(cb, largeList_.handle(), largeList_.handle(), 2, firstLate);
    const VkBufferCopy clipFirstLate{12, 16, 4};  // clipCount -> clipFirst (raster_fetch.glsl)
    if (clip) vkCmdCopyBuffer(cb, clipList_.handle(), clipList_.handle(), 1, &clipFirstLate);
    pyramid_->buildFromBuffer(cb, vis_.handle());
    timer.mark(cb, "pyramid");
    // Its first barrier orders the copies above before its reset, its second makes them visible to compute.
    culler_->record(cb, scene_.clusters(), clusterCount, camera, &*pyramid_, {}, CullPhase::Late, lods, scene_.cullInstances(),
                    scene_.cullInstanceCount(), scene_.cullNodes(), scene_.instances());
    if (counters) {
      vkCmdCopyBuffer(cb, culler_->counts(), cullReadback_.handle(), 1, &toReadback[1]);
      vk::bufferBarrier(cb, vk::kCopyWrite, vk::kHostRead);
    }
    timer.mark(cb, "cull");
  }
  if (clusterCount > 0) rasterise("raster", "raster clip", "raster large");
  vk::bufferBarrier(cb, vk::kComputeWrite, kReaders | vk::kCopyRead);
  if (counters) {  // the counters of this frame (RenderSettings::counters)
    const VkDeviceSize at = kReadbackSize * VkDeviceSize(frame);
    const VkBufferCopy handOffCount{0, at, 4};  // VkDrawIndirectCommand::vertexCount
    vkCmdCopyBuffer(cb, hwList_.handle(), handOffReadback_.handle(), 1, &handOffCount);
    const VkBufferCopy clipCount{12, at + 4, 4};  // clipCount
    vkCmdCopyBuffer(cb, clipList_.handle(), handOffReadback_.handle(), 1, &clipCount);
    const VkBufferCopy medium[2] = {{16, at + 8, 8}, {32, at + 16, 8}};  // mediumFound, mediumStored
    vkCmdCopyBuffer(cb, largeList_.handle(), handOffReadback_.handle(), 2, medium);
    vk::bufferBarrier(cb, vk::kCopyWrite, vk::kHostRead);
  }
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};  // no attachments: fragments only do the atomic
  ri.renderArea = {{0, 0}, extent_};
  ri.layerCount = 1;
  vkCmdBeginRendering(cb, &ri);
  vk::setFullViewport(cb, extent_);
  bind(hardware_);
  vkCmdDrawIndirect(cb, hwList_.handle(), 0, 1, sizeof(VkDrawIndirectCommand));
  vkCmdEndRendering(cb);
  timer.mark(cb, "raster hw");
}

}  // namespace rtr::render
