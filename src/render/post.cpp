#include "render/post.hpp"

#include "core/error.hpp"
#include "mosaic.h"
#include "vk/commands.hpp"
#include "vk/context.hpp"

namespace rtr::render {

const char* toString(MosaicMode mode) {
  switch (mode) {
    case MosaicMode::Off: return "off";
    case MosaicMode::Compute: return "compute";
    case MosaicMode::Graphics: return "graphics";
  }
  return "?";
}

MosaicPass::MosaicPass(const vk::Context& ctx) : ctx_(ctx) {
  compute_ = vk::makeComputePipeline(ctx, vk::loadShader("mosaic.comp"), {.pushDescriptorSets = {0}});
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

void MosaicPass::record(VkCommandBuffer cb, VkImageView input, VkImage output, VkImageView outputView,
                        VkFormat outputFormat, VkExtent2D extent, MosaicMode mode, VkImageLayout outputFinalLayout) {
  const VkExtent2D block = mode == MosaicMode::Off ? VkExtent2D{1, 1} : block_;
  const shader::MosaicPush push{{int(block.width), int(block.height)}, {int(extent.width), int(extent.height)}};
  const bool raster = mode == MosaicMode::Graphics;
  const VkImageLayout work = raster ? VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_GENERAL;
  const VkPipelineStageFlags2 stage = raster ? VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT : VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
  const VkAccessFlags2 write = raster ? VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT : VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;

  // Discard: after every earlier command (previous readers of the output, the acquire wait), no access
  // to make visible since nothing is kept.
  vk::barrier(cb, {{output, VK_IMAGE_LAYOUT_UNDEFINED, work, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, stage,
                    VK_ACCESS_2_NONE, write, 0, 1}});
  if (raster) {
    const vk::Pipeline& p = graphics(outputFormat);
    vk::beginColorRendering(cb, outputView, extent, VK_ATTACHMENT_LOAD_OP_DONT_CARE);  // the triangle covers all
    p.bind(cb);
    vk::DescriptorWriter(ctx_, p.layout, 0, VK_NULL_HANDLE)
        .image(0, input, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL)
        .push(cb, p);
    p.push(cb, push);
    vkCmdDraw(cb, 3, 1, 0, 0);
    vkCmdEndRendering(cb);
  } else {
    const vk::Pipeline& c = compute_;
    c.bind(cb);
    vk::DescriptorWriter(ctx_, c.layout, 0, VK_NULL_HANDLE)
        .image(0, input, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL)
        .image(1, outputView, VK_IMAGE_LAYOUT_GENERAL)
        .push(cb, c);
    c.push(cb, push);
    // One thread per block; the workgroup's shape is the shader's (reflected) local size.
    const auto& group = c.layout.interface().stages.at(0).localSize;
    const uint32_t blocksX = (extent.width + block.width - 1) / block.width;
    const uint32_t blocksY = (extent.height + block.height - 1) / block.height;
    vkCmdDispatch(cb, (blocksX + group[0] - 1) / group[0], (blocksY + group[1] - 1) / group[1], 1);
  }
  // Presentation is ordered by the submit's signal semaphore: only the layout change is needed then.
  const bool present = outputFinalLayout == VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  vk::barrier(cb, {{output, work, outputFinalLayout, stage, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, write,
                    present ? VK_ACCESS_2_NONE : VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT, 0, 1}});
}

}  // namespace rtr::render
