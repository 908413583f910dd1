#include "render/post.hpp"

#include "core/error.hpp"
#include "mosaic.h"
#include "vk/commands.hpp"
#include "vk/context.hpp"

namespace rtr::render {

MosaicPass::MosaicPass(const vk::Context& ctx, std::optional<vk::Pipeline> compute) : ctx_(ctx), compute_(std::move(compute)) {}

vk::Pipeline MosaicPass::makeCompute(const vk::Context& ctx) {
  return vk::makeComputePipeline(ctx, vk::loadShader("mosaic.comp"), {.pushDescriptorSets = {0}});
}

void MosaicPass::setBlock(VkExtent2D block) {
  if (block.width == 0 || block.height == 0) throw Error("MosaicPass: empty block");
  block_ = block;
}

const vk::Pipeline& MosaicPass::graphics(VkFormat format) {
  auto it = graphics_.find(format);
  if (it != graphics_.end()) return it->second;
  vk::GraphicsDesc d;
  d.modules = {vk::loadShader("mosaic.vert"), vk::loadShader("mosaic.frag")};
  d.cullMode = VK_CULL_MODE_NONE;
  d.depthTest = d.depthWrite = false;
  d.colorFormats = {format};
  return graphics_.emplace(format, vk::makeGraphicsPipeline(ctx_, d, {.pushDescriptorSets = {0}})).first->second;
}

void MosaicPass::record(VkCommandBuffer cb, vk::TrackedImage input, VkImageView inputView, vk::TrackedImage output,
                        VkImageView outputView, VkFormat outputFormat, VkExtent2D extent, MosaicMode mode) {
  const VkExtent2D block = mode == MosaicMode::Off ? VkExtent2D{1, 1} : block_;
  const shader::MosaicPush push{{int(block.width), int(block.height)}, {int(extent.width), int(extent.height)}};
  const bool raster = mode == MosaicMode::Graphics;
  const VkPipelineStageFlags2 stage =
      raster ? VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT : VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
  vk::require(
      cb, {{input, vk::Use::Sampled, raster ? VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT : VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT},
           {output, raster ? vk::Use::ColorAttachment : vk::Use::Storage, stage, true}});
  if (raster) {
    const vk::Pipeline& p = graphics(outputFormat);
    vk::beginColorRendering(cb, outputView, extent, VK_ATTACHMENT_LOAD_OP_DONT_CARE);  // the triangle covers all
    p.bind(cb);
    vk::DescriptorWriter(ctx_, p.layout, 0, VK_NULL_HANDLE)
        .image(0, inputView, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL)
        .push(cb, p);
    p.push(cb, push);
    vkCmdDraw(cb, 3, 1, 0, 0);
    vkCmdEndRendering(cb);
  } else {
    if (!compute_) compute_ = makeCompute(ctx_);
    const vk::Pipeline& c = *compute_;
    c.bind(cb);
    vk::DescriptorWriter(ctx_, c.layout, 0, VK_NULL_HANDLE)
        .image(0, inputView, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL)
        .image(1, outputView, VK_IMAGE_LAYOUT_GENERAL)
        .push(cb, c);
    c.push(cb, push);
    // One thread per block.
    c.dispatch(cb, (extent.width + block.width - 1) / block.width, (extent.height + block.height - 1) / block.height);
  }
}

}  // namespace rtr::render
