#pragma once
// The CPU ray tracer inside the viewer (key R): traces the current view on worker threads and shows the
// image over the raster one, filling in tile by tile, as the course framework's ray-traced half did.
// Key X: the same with the renderer's shading model, then the per-pixel error map against the raster frame.
#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <vulkan/vulkan.h>

#include "core/image.hpp"
#include "trace/tracer.hpp"
#include "vk/frame_ring.hpp"
#include "vk/resources.hpp"

namespace rtr::view {

class TraceOverlay {
 public:
  TraceOverlay(const vk::Context& ctx, const Scene& scene) : ctx_(ctx), scene_(scene) {}
  ~TraceOverlay() { stop(); }

  // Starts tracing `settings` (its size, pose and lens set by the caller); cancels a running trace. With
  // `raster` (the raster frame of the same view, sRGB bytes, same size), the finished trace is replaced by
  // the error map of raster against it (core/compare.hpp), and status() gives the mean and max error.
  void start(const trace::TraceSettings& settings, std::optional<ImageRGBA8> raster = std::nullopt);
  void stop();  // cancels and hides
  bool visible() const { return visible_; }
  bool errorMapShown() const { return visible_ && errorMapShown_; }  // the error map, not a trace or its failure
  // The error map's scale: grey = the largest channel error, white at this many 8-bit steps; red beyond it
  // (the reference tests' threshold, docs/reference-tests.md).
  static constexpr int kErrorThreshold = 3;
  std::string status() const;

  // Records a copy of the traced image over `image` (in TRANSFER_DST_OPTIMAL, `format` BGRA or RGBA UNORM,
  // holding sRGB-encoded bytes). The overlay keeps the image on the GPU: only when tiles have finished since
  // the last frame do its bytes go through the frame's upload arena into it (a frame still in flight keeps
  // its copy: frames record and submit in order, and the image's tracked state orders the rewrite after
  // the earlier frame's read). A steady overlay costs one GPU-side image copy a frame.
  void recordCopy(vk::Frame& frame, VkImage image, VkFormat format, VkExtent2D extent);
  // Waits for the trace to finish (or be cancelled); then cpuImage() is final.
  void wait() {
    if (worker_.joinable()) worker_.join();
  }
  // The image the overlay shows, as sRGB bytes (RGBA): the trace, or its error map.
  ImageRGBA8 cpuImage();

 private:
  const vk::Context& ctx_;
  const Scene& scene_;
  std::unique_ptr<trace::Tracer> tracer_;  // built on the first R: the BVH is only made when asked for
  std::thread worker_;
  std::atomic<bool> cancel_{false}, dirty_{false}, visible_{false};
  std::atomic<uint32_t> tilesDone_{0}, tilesTotal_{0};
  std::atomic<bool> showError_{false}, errorMapShown_{false};  // errorMap_ and errorText_ are final once this is set
  std::mutex mutex_;                                           // guards image_ against a concurrent restart
  ImageF image_;
  ImageRGBA8 errorMap_;
  std::string errorText_;
  vk::Image shown_;  // cpuImage() in the target's format, refreshed when tiles have finished
};

}  // namespace rtr::view
