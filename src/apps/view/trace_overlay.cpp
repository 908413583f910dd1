#include "trace_overlay.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <string>

#include "core/compare.hpp"

#include "vk/context.hpp"
#include "vk/image_state.hpp"

namespace rtr::view {

void TraceOverlay::start(const trace::TraceSettings& settings, std::optional<ImageRGBA8> raster) {
  stop();
  showError_ = false;
  errorMapShown_ = false;
  if (!tracer_) tracer_ = std::make_unique<trace::Tracer>(scene_);
  {
    std::lock_guard lock(mutex_);
    image_ = {settings.width, settings.height, std::vector<glm::vec4>(size_t(settings.width) * settings.height)};
  }
  cancel_ = false;
  tilesDone_ = 0;
  const uint32_t tile = settings.tileSize;
  tilesTotal_ = ((settings.width + tile - 1) / tile) * ((settings.height + tile - 1) / tile);
  visible_ = true;
  worker_ = std::thread([this, settings, raster = std::move(raster)] {
    std::lock_guard lock(mutex_);
    trace::RenderStats st;
    try {  // a texture file gone since the GPU loaded it: say so instead of ending the viewer
      st = tracer_->render(
          settings, image_,
          [this](const trace::TileRect&) {
            ++tilesDone_;
            dirty_ = true;
          },
          &cancel_);
    } catch (const std::exception& e) {
      errorText_ = std::string("ray trace failed: ") + e.what();
      errorMap_ = toSrgb8(image_);  // shown in place of an error map: same size as the overlay
      showError_ = true;
      dirty_ = true;
      return;
    }
    if (raster && !st.cancelled) {
      const CompareResult r = compareEdgeTolerant(*raster, toSrgb8(image_), kErrorThreshold);
      errorMap_ = r.errorMap;
      char text[200];
      std::snprintf(text, sizeof text,
                    "error map, raster vs CPU trace: mean %.2f, max %.0f (8-bit steps)\n"
                    "%.2f%% of pixels > %d steps beyond 3x3 edge tolerance (red); trace %.2f s",
                    r.meanAbsError, r.maxAbsError, 100.0 * r.failingFraction, kErrorThreshold, st.seconds);
      errorText_ = text;
      errorMapShown_ = true;
      showError_ = true;
    }
    dirty_ = true;
  });
}

void TraceOverlay::stop() {
  cancel_ = true;
  if (worker_.joinable()) worker_.join();
  visible_ = false;
}

std::string TraceOverlay::status() const {
  if (!visible_) return "";
  if (showError_) return errorText_;
  return "ray traced " + std::to_string(tilesDone_.load()) + "/" + std::to_string(tilesTotal_.load()) + " tiles";
}

ImageRGBA8 TraceOverlay::cpuImage() { return showError_ ? errorMap_ : toSrgb8(image_); }

void TraceOverlay::recordCopy(vk::Frame& frame, VkImage image, VkFormat format, VkExtent2D extent) {
  const uint32_t w = std::min(extent.width, image_.width), h = std::min(extent.height, image_.height);
  if (w == 0 || h == 0) return;
  const VkExtent2D size{image_.width, image_.height};
  const bool resized = !shown_.handle() || shown_.format() != format || shown_.extent().width != size.width ||
                       shown_.extent().height != size.height;
  if (dirty_.exchange(false) || resized) {
    if (resized) {  // the old image may still be read by a frame in flight: free it with this one
      frame.defer([old = std::make_shared<vk::Image>(std::move(shown_))] {});
      shown_ = vk::Image(
          ctx_, {size, format, 1, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, 0, 0, "traced image"});
    }
    // Tiles still being written may show half done; the next refresh completes them.
    ImageRGBA8 bytes = cpuImage();
    if (format == VK_FORMAT_B8G8R8A8_UNORM)
      for (size_t i = 0; i < bytes.pixels.size(); i += 4) std::swap(bytes.pixels[i], bytes.pixels[i + 2]);
    const vk::UploadArena::Slice slice = frame.upload(bytes.pixels.size(), 16);
    std::memcpy(slice.data, bytes.pixels.data(), bytes.pixels.size());
    vk::require(frame.cb, shown_.tracked(), vk::Use::CopyDst, VK_PIPELINE_STAGE_2_COPY_BIT, true);
    VkBufferImageCopy region{};
    region.bufferOffset = slice.offset;
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {size.width, size.height, 1};
    vkCmdCopyBufferToImage(frame.cb, slice.buffer, shown_.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  }
  vk::require(frame.cb, shown_.tracked(), vk::Use::CopySrc, VK_PIPELINE_STAGE_2_COPY_BIT);
  VkImageCopy region{};
  region.srcSubresource = region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.extent = {w, h, 1};
  vkCmdCopyImage(frame.cb, shown_.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                 &region);
}

}  // namespace rtr::view
