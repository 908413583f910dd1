#pragma once
// The viewer's frames on a window surface: swapchain, frames in flight, the renderer, and what the viewer
// draws over its frame (the traced image, the settings panel). The window app gives it a view per frame.
#include <optional>
#include <string>

#include "core/image.hpp"
#include "render/renderer.hpp"
#include "imgui_pass.hpp"
#include "trace_overlay.hpp"
#include "vk/frame_ring.hpp"
#include "vk/swapchain.hpp"

namespace rtr::view {

struct ViewFrameInput {
  CameraPose pose;
  Lens lens;
  render::RenderSettings settings;
  TraceOverlay* trace = nullptr;      // drawn over the frame while visible
  const ImDrawData* panel = nullptr;  // the settings panel; none: hidden
  bool readBack = false;              // return the frame (before the panel is drawn)
};

class ViewFrames {
 public:
  static constexpr uint32_t kFramesInFlight = 2;
  ViewFrames(const vk::Context& ctx, VkSurfaceKHR surface, VkExtent2D windowExtent, const render::GpuScene& scene,
             render::Renderer::Prepared prepared = {});

  // Renders and presents one frame. False: the swapchain was out of date, nothing was drawn. With
  // in.readBack, waits for the frame and fills `shot` (RGBA bytes).
  bool frame(VkExtent2D windowExtent, const ViewFrameInput& in, ImageRGBA8* shot = nullptr);
  void markStale() { swapchain_.markStale(); }
  VkExtent2D extent() const { return swapchain_.extent(); }
  bool canReadBack() const { return swapchain_.usage() & VK_IMAGE_USAGE_TRANSFER_SRC_BIT; }
  render::Renderer& renderer() { return renderer_; }
  // Per-pass GPU times of the most recently completed frame, the panel's last.
  std::vector<std::pair<std::string, double>> gpuTimes() const;
  // Hot reload of the renderer's and the panel's pipelines; a failure throws and keeps the old ones.
  void rebuildPipelines();

 private:
  const vk::Context& ctx_;
  vk::Swapchain swapchain_;
  render::Renderer renderer_;
  ImGuiPass panel_;
  vk::Buffer shot_;
  uint32_t lastIndex_ = 0;
  vk::FrameRing ring_;  // last: destroyed first, waiting for the frames that use the members above
};

}  // namespace rtr::view
