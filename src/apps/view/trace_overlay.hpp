#pragma once
// The CPU ray tracer inside the viewer (key R): traces the current view on worker threads and shows the
// image over the raster one, filling in tile by tile, as the course framework's ray-traced half did.
#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <vulkan/vulkan.h>

#include "core/image.hpp"
#include "trace/tracer.hpp"
#include "vk/resources.hpp"

namespace rtr::view {

class TraceOverlay {
 public:
  explicit TraceOverlay(const Scene& scene) : scene_(scene) {}
  ~TraceOverlay() { stop(); }

  // Starts tracing `settings` (its size, pose and lens set by the caller); cancels a running trace.
  void start(const trace::TraceSettings& settings);
  void stop();  // cancels and hides
  bool visible() const { return visible_; }
  std::string status() const;

  // Records a copy of the traced image over `image` (in TRANSFER_DST_OPTIMAL, `format` BGRA or RGBA UNORM,
  // holding sRGB-encoded bytes). Refreshes `staging` from the CPU image when tiles have finished.
  void recordCopy(const vk::Context& ctx, VkCommandBuffer cb, VkImage image, VkFormat format, VkExtent2D extent,
                  vk::Buffer& staging);

 private:
  const Scene& scene_;
  std::unique_ptr<trace::Tracer> tracer_;  // built on the first R: the BVH is only made when asked for
  std::thread worker_;
  std::atomic<bool> cancel_{false}, dirty_{false}, visible_{false};
  std::atomic<uint32_t> tilesDone_{0}, tilesTotal_{0};
  std::mutex mutex_;  // guards image_ against a concurrent restart
  ImageF image_;
};

}  // namespace rtr::view
