#include "view_frames.hpp"

#include <cstring>

#include "vk/commands.hpp"

namespace rtr::view {

ViewFrames::ViewFrames(const vk::Context& ctx, VkSurfaceKHR surface, VkExtent2D windowExtent, const render::GpuScene& scene,
                       render::Renderer::Prepared prepared)
    : ctx_(ctx),
      swapchain_(ctx, surface, windowExtent),
      renderer_(ctx, scene, kFramesInFlight, std::move(prepared)),
      panel_(ctx, kFramesInFlight),
      ring_(ctx, kFramesInFlight) {}

bool ViewFrames::frame(VkExtent2D windowExtent, const ViewFrameInput& in, ImageRGBA8* shot) {
  vk::Frame& f = ring_.begin();
  const std::optional<uint32_t> acquired = swapchain_.acquire(f.acquired, windowExtent);
  if (!acquired) return false;
  const uint32_t imageIndex = *acquired;
  lastIndex_ = f.index;
  const VkExtent2D e = swapchain_.extent();
  const VkFormat format = swapchain_.format();
  const bool readBack = in.readBack && canReadBack();
  if (readBack)
    shot_ = vk::Buffer(ctx_, VkDeviceSize(e.width) * e.height * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback);
  const bool showTrace = in.trace && in.trace->visible() && (swapchain_.usage() & VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  // The post pass (the shading pass where it writes the target) is the first to touch the swapchain image,
  // in compute or as a colour attachment, after the acquire semaphore waited at those stages: its barrier
  // chains to that wait.
  constexpr VkPipelineStageFlags2 kAcquireWait =
      VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
  vk::ImageState acquiredState{VK_IMAGE_LAYOUT_UNDEFINED, kAcquireWait, VK_ACCESS_2_NONE, 0};
  const vk::TrackedImage image{swapchain_.image(imageIndex), &acquiredState, "swapchain image"};
  render::FrameContext fc{f, in.pose, in.lens, in.settings, {image, swapchain_.view(imageIndex), format, e}};
  renderer_.frame(fc);
  if (showTrace) {  // the traced image over the raster one
    vk::require(f.cb, image, vk::Use::CopyDst, VK_PIPELINE_STAGE_2_COPY_BIT);
    in.trace->recordCopy(f, image.image, format, e);
  }
  if (readBack) {
    vk::require(f.cb, image, vk::Use::CopySrc, VK_PIPELINE_STAGE_2_COPY_BIT);
    vk::copyImageToHost(f.cb, image.image, e, shot_.handle());
  }
  // The panel comes last, after any read-back copy: screenshots never contain it.
  if (in.panel) panel_.record(f, *in.panel, image, fc.target.view, format, e);
  else panel_.skip(f.index);
  vk::require(f.cb, image, vk::Use::Present, VK_PIPELINE_STAGE_2_NONE);
  ring_.submit(f, f.acquired, kAcquireWait, swapchain_.renderDone(imageIndex));
  swapchain_.present(imageIndex);
  if (readBack) {
    ring_.waitIdle();
    if (!shot) return true;
    shot_.invalidate();
    *shot = {e.width, e.height, std::vector<uint8_t>(size_t(e.width) * e.height * 4)};
    std::memcpy(shot->pixels.data(), shot_.mapped(), shot->pixels.size());
    if (format == VK_FORMAT_B8G8R8A8_UNORM)
      for (size_t i = 0; i < shot->pixels.size(); i += 4) std::swap(shot->pixels[i], shot->pixels[i + 2]);
  }
  return true;
}

std::vector<std::pair<std::string, double>> ViewFrames::gpuTimes() const {
  const uint32_t done = (lastIndex_ + 1) % kFramesInFlight;
  auto times = renderer_.gpuTimes(done);
  if (const auto ms = panel_.gpuMs(done)) times.push_back({"panel", *ms});
  return times;
}

void ViewFrames::rebuildPipelines() {
  renderer_.rebuildPipelines();
  panel_.rebuildPipelines();
}

}  // namespace rtr::view
