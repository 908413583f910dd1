#pragma once
// The mosaic post-process (brief part 2, section 1.7): every block of 5x3 output pixels takes the value
// of one pixel inside it (the block's centre, clamped into the image; shaders/shared/mosaic.h), read
// from the scene's linear-light colour image and written sRGB-encoded into a UNORM output (swapchain
// image or headless target). Compute (default) and graphics (full-screen triangle, dynamic rendering,
// no subpasses) give bit-identical bytes; Off is a plain copy with the same encode, in compute.
//
// MosaicPass::record requires (vk/image_state.hpp) the input sampled in the stage that reads it and the
// output written (previous contents discarded): STORAGE usage for Compute/Off, COLOR_ATTACHMENT usage for
// Graphics. The output is left as written; the caller requires what comes next (copy, present).
#include <array>
#include <map>
#include <optional>

#include <vulkan/vulkan.h>

#include "core/enum_names.hpp"
#include "vk/pipeline.hpp"

namespace rtr::render {

enum class MosaicMode { Off, Compute, Graphics };
constexpr std::array<EnumName<MosaicMode>, 3> enumNames(MosaicMode) {
  return {{{MosaicMode::Off, "off"}, {MosaicMode::Compute, "compute"}, {MosaicMode::Graphics, "graphics"}}};
}

class MosaicPass {
 public:
  // The compute pipeline (Compute and Off): `compute` where made ahead (makeCompute), else on first use;
  // graphics ones per format, on first use.
  explicit MosaicPass(const vk::Context& ctx, std::optional<vk::Pipeline> compute = {});
  static vk::Pipeline makeCompute(const vk::Context& ctx);

  void setBlock(VkExtent2D block);  // 5x3 by default
  VkExtent2D block() const { return block_; }

  void record(VkCommandBuffer cb, vk::TrackedImage input, VkImageView inputView, vk::TrackedImage output, VkImageView outputView,
              VkFormat outputFormat, VkExtent2D extent, MosaicMode mode);

 private:
  const vk::Pipeline& graphics(VkFormat format);
  const vk::Context& ctx_;
  VkExtent2D block_{5, 3};
  std::optional<vk::Pipeline> compute_;
  std::map<VkFormat, vk::Pipeline> graphics_;
};

}  // namespace rtr::render
