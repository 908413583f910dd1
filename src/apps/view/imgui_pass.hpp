#pragma once
// Draws Dear ImGui's draw lists over a finished frame with a pipeline of our own (shaders/render/imgui.*:
// layout by reflection, dynamic rendering, vertices through the frame's upload arena). ImGui 1.86's
// Vulkan back-end needs a render pass, hence not used. The font atlas is the only texture.
#include <map>
#include <optional>
#include <vector>

#include <vulkan/vulkan.h>

#include "vk/commands.hpp"
#include "vk/frame_ring.hpp"
#include "vk/pipeline.hpp"
#include "vk/resources.hpp"

struct ImDrawData;

namespace rtr::view {

class ImGuiPass {
 public:
  // Uploads the current ImGui context's font atlas (built at whatever size the app set up before).
  ImGuiPass(const vk::Context& ctx, uint32_t framesInFlight);

  // Draws `data` over `image` (its contents kept), timed as its own pass.
  void record(vk::Frame& frame, const ImDrawData& data, vk::TrackedImage image, VkImageView view, VkFormat format,
              VkExtent2D extent);
  // Marks `frame` as drawing nothing (its timer then reports no time).
  void skip(uint32_t frame) { drawn_[frame] = false; }
  // The pass's GPU time in `frame`'s last use, if it drew.
  std::optional<double> gpuMs(uint32_t frame) const;
  // Hot reload: new pipelines from the shader folder; a failure throws and keeps the old ones.
  void rebuildPipelines();

 private:
  vk::Pipeline makePipeline(VkFormat format) const;
  const vk::Context& ctx_;
  vk::Image font_;
  vk::Sampler sampler_;
  std::map<VkFormat, vk::Pipeline> pipelines_;
  std::vector<vk::GpuTimer> timers_;
  std::vector<bool> drawn_;
};

}  // namespace rtr::view
