#include "render/headless.hpp"

#include <glm/gtc/packing.hpp>

#include "vk/context.hpp"

namespace rtr::render {

HeadlessRenderer::HeadlessRenderer(const vk::Context& ctx, const GpuScene& scene, VkExtent2D extent, Renderer::Prepared prepared)
    : ctx_(ctx), extent_(extent), renderer_(ctx, scene, 1, std::move(prepared)), ring_(ctx, 1) {
  resize(extent);
}

void HeadlessRenderer::resize(VkExtent2D extent) {
  ring_.waitIdle();  // every frame is waited for already; the images and buffers below are free
  extent_ = extent;
  target_ = vk::Image(ctx_, {extent, VK_FORMAT_R8G8B8A8_UNORM, 1,
                             VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                             0, 0, "headless target"});
  const VkDeviceSize pixels = VkDeviceSize(extent.width) * extent.height;
  readback_ = vk::Buffer(ctx_, pixels * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback, "target readback");
  colorReadback_ = {}, idReadback_ = {};  // made at the new size when next needed
}

void HeadlessRenderer::frame(const CameraPose& pose, const Lens& lens, const RenderSettings& settings,
                             const std::function<void(VkCommandBuffer)>& after, bool readSceneColor) {
  FrameContext fc{ring_.begin(), pose, lens, settings, target(), readSceneColor};
  renderer_.frame(fc);
  if (after) after(fc.frame.cb);
  ring_.submit(fc.frame);
  ring_.waitIdle();
}

HeadlessFrame HeadlessRenderer::render(const CameraPose& pose, const Lens& lens, const RenderSettings& settings, int frames,
                                       bool readSceneColor) {
  const VkDeviceSize pixels = VkDeviceSize(extent_.width) * extent_.height;
  if (readSceneColor && !colorReadback_.handle())
    colorReadback_ = vk::Buffer(ctx_, pixels * 8, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback, "colour readback");
  for (int f = 0; f < frames; ++f) {
    const bool last = f + 1 == frames;
    frame(
        pose, lens, settings,
        [&](VkCommandBuffer cb) {
          if (!last) return;
          vk::require(cb, target_.tracked(), vk::Use::CopySrc, VK_PIPELINE_STAGE_2_COPY_BIT);
          vk::copyImageToHost(cb, target_.handle(), extent_, readback_.handle());
          if (readSceneColor) {
            const vk::Image& color = renderer_.sceneColor();
            vk::require(cb, color.tracked(), vk::Use::CopySrc, VK_PIPELINE_STAGE_2_COPY_BIT);
            vk::copyImageToHost(cb, color.handle(), extent_, colorReadback_.handle());
          }
        },
        readSceneColor && last);
  }
  HeadlessFrame out;
  out.gpuTimes = renderer_.gpuTimes(0);
  readback_.invalidate();
  const auto* mapped = static_cast<const uint8_t*>(readback_.mapped());
  out.image = {extent_.width, extent_.height, std::vector<uint8_t>(mapped, mapped + pixels * 4)};  // one pass, not zeroed first
  if (readSceneColor) {
    colorReadback_.invalidate();
    const auto* half = static_cast<const uint16_t*>(colorReadback_.mapped());
    out.sceneColor = {extent_.width, extent_.height, std::vector<glm::vec4>(pixels)};
    for (VkDeviceSize i = 0; i < pixels; ++i)
      for (int c = 0; c < 4; ++c) out.sceneColor.pixels[i][c] = glm::unpackHalf1x16(half[i * 4 + c]);
  }
  return out;
}

std::vector<uint32_t> HeadlessRenderer::ids(const CameraPose& pose, const Lens& lens, const RenderSettings& settings) {
  const VkDeviceSize pixels = VkDeviceSize(extent_.width) * extent_.height;
  if (!idReadback_.handle())
    idReadback_ = vk::Buffer(ctx_, pixels * 8, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback, "id readback");
  uint32_t bytes = 0;
  RenderSettings keep = settings;
  keep.keepIds = true;  // not cleared by the shading pass
  frame(pose, lens, keep, [&](VkCommandBuffer cb) { bytes = renderer_.copyIds(cb, idReadback_.handle()); });
  idReadback_.invalidate();
  const auto* words = static_cast<const uint32_t*>(idReadback_.mapped());
  std::vector<uint32_t> out(pixels);
  for (VkDeviceSize i = 0; i < pixels; ++i) out[i] = words[i * (bytes / 4)];  // the low half of a 64-bit entry
  return out;
}

std::vector<std::vector<std::pair<std::string, double>>> HeadlessRenderer::bench(const CameraPose& pose, const Lens& lens,
                                                                                 const RenderSettings& settings, int frames) {
  std::vector<std::vector<std::pair<std::string, double>>> out;
  for (int f = 0; f < frames; ++f) {
    frame(pose, lens, settings);
    out.push_back(renderer_.gpuTimes(0));
  }
  return out;
}

}  // namespace rtr::render
