#include "render/raster.hpp"

#include <algorithm>
#include <cstdlib>
#include <string>

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

ComputeRaster::ComputeRaster(const vk::Context& ctx, const GpuScene& scene) : ctx_(ctx), scene_(scene) {
  const vk::LayoutOptions push{.pushDescriptorSets = {0}};
  clear_ = vk::makeComputePipeline(ctx, vk::loadShader("raster_clear.comp"), push);
  uint32_t sharedArea = RASTER_SHARED_AREA;
  if (const char* env = std::getenv("RTR_RASTER_SHARED_AREA")) sharedArea = uint32_t(std::stoul(env));
  raster_ = vk::makeComputePipeline(ctx, vk::loadShader("raster.comp"), push, {{0, sharedArea}});
  large_ = vk::makeComputePipeline(ctx, vk::loadShader("raster_large.comp"), push, {{0, sharedArea}});
  vk::GraphicsDesc d;
  d.modules = {vk::loadShader("raster_hw.vert"), vk::loadShader("raster_hw.frag")};
  d.cullMode = VK_CULL_MODE_NONE;  // the fragment stage culls by the cluster's flags
  d.depthTest = d.depthWrite = false;
  vk::LayoutOptions options = push;
  options.runtimeArrayCounts[{1, 0}] = std::max(1u, scene.textureCount());
  hardware_ = vk::makeGraphicsPipeline(ctx, d, options);
  textures_ = vk::DescriptorSets(ctx, hardware_.layout, 1);
  auto textures = scene.textureDescriptors();
  if (!textures.empty()) vk::DescriptorWriter(ctx, hardware_.layout, 1, textures_.get(1)).images(0, textures).commit();
  // Every triangle at most once in the hand-off list, after its VkDrawIndirectCommand.
  uint64_t triangles = 0;
  for (size_t k = 0; k < kDrawKindCount; ++k)
    for (const DrawItem& di : scene.draws(DrawKind(k))) triangles += di.indexCount / 3;
  hwList_ = vk::Buffer(ctx, sizeof(VkDrawIndirectCommand) + 4 * std::max<uint64_t>(triangles, 1),
                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, vk::MemoryUse::Device,
                       "raster hand-off");
  largeList_ = vk::Buffer(ctx, 16 + 8 * VkDeviceSize(RASTER_LARGE_CAPACITY), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                          vk::MemoryUse::Device, "raster tiles");
}

void ComputeRaster::resize(VkExtent2D extent) {
  if (extent.width == extent_.width && extent.height == extent_.height) return;
  vis_ = vk::Buffer(ctx_, VkDeviceSize(extent.width) * extent.height * 8,
                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUse::Device,
                    "visibility (64-bit)");
  extent_ = extent;
}

void ComputeRaster::record(VkCommandBuffer cb, const vk::UploadArena::Slice& uniforms, uint32_t primitiveBits,
                           vk::GpuTimer& timer) {
  // A scene may lack one index width or texcoords: any storage buffer fills that binding (nothing reads it).
  const VkBuffer i16 = scene_.indices16() ? scene_.indices16() : scene_.indices32();
  const VkBuffer i32 = scene_.indices32() ? scene_.indices32() : scene_.indices16();
  const VkBuffer uv = scene_.texcoords() ? scene_.texcoords() : scene_.positions();
  auto bind = [&](const vk::Pipeline& p) {
    p.bind(cb);
    vk::DescriptorWriter w(ctx_, p.layout, 0, VK_NULL_HANDLE);
    for (const vk::ReflectedBinding& b : p.layout.interface().bindings) {
      if (b.set != 0) continue;
      const VkBuffer buffers[] = {uniforms.buffer, scene_.clusters(), scene_.drawInfo(), scene_.positions(),
                                  i32, i16, vis_.handle(), hwList_.handle(), scene_.materials(), uv,
                                  largeList_.handle()};
      if (b.binding == 0) w.buffer(0, uniforms.buffer, uniforms.offset, sizeof(shader::FrameUniforms));
      else w.buffer(b.binding, buffers[b.binding]);
    }
    w.push(cb, p);
    p.push(cb, shader::RasterPush{extent_.width, extent_.height, primitiveBits, scene_.clusterCount()});
  };
  // The previous frame's readers of both buffers (shading, the indirect draw) before they are cleared.
  vk::memoryBarrier(cb,
                    VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
                        VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT |
                        VK_PIPELINE_STAGE_2_COPY_BIT,
                    VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |
                        VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_2_TRANSFER_READ_BIT,
                    VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  bind(clear_);
  const uint32_t pixels = extent_.width * extent_.height;
  vkCmdDispatch(cb, (pixels + RASTER_CLEAR_GROUP - 1) / RASTER_CLEAR_GROUP, 1, 1);
  timer.mark(cb, "clear");
  vk::memoryBarrier(cb, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                    VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                    VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  if (scene_.clusterCount() > 0) {
    bind(raster_);
    // Workgroup counts per dimension are limited (65535 on many devices): clusters over x, then y.
    const uint32_t maxX = std::min(ctx_.properties().limits.maxComputeWorkGroupCount[0], 65535u);
    const uint32_t x = std::min(scene_.clusterCount(), maxX);
    vkCmdDispatch(cb, x, (scene_.clusterCount() + x - 1) / x, 1);
    timer.mark(cb, "raster");
    vk::memoryBarrier(cb, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    bind(large_);
    vkCmdDispatch(cb, RASTER_LARGE_GROUPS, 1, 1);
    timer.mark(cb, "raster large");
  }
  vk::memoryBarrier(cb, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                    VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT |
                        VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                    VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT |
                        VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};  // no attachments: fragments only do the atomic
  ri.renderArea = {{0, 0}, extent_};
  ri.layerCount = 1;
  vkCmdBeginRendering(cb, &ri);
  vk::setFullViewport(cb, extent_);
  bind(hardware_);
  if (hardware_.layout.setCount() > 1) hardware_.bindSet(cb, 1, textures_.get(1));
  vkCmdDrawIndirect(cb, hwList_.handle(), 0, 1, sizeof(VkDrawIndirectCommand));
  vkCmdEndRendering(cb);
  timer.mark(cb, "raster hw");
}

}  // namespace rtr::render
