#include "render/text_overlay.hpp"

#include <algorithm>
#include <vector>

#include <stb_easy_font.h>

#include "text.h"
#include "vk/commands.hpp"
#include "vk/context.hpp"

namespace rtr::render {
namespace {

constexpr uint32_t kCapacity = 16384;  // rectangles per frame: about 2,500 characters
constexpr float kMargin = 4.0f;        // font units of backdrop around the text

}  // namespace

TextOverlay::TextOverlay(const vk::Context& ctx, uint32_t framesInFlight) : ctx_(ctx) {
  for (uint32_t i = 0; i < framesInFlight; ++i)
    frames_.push_back({vk::Buffer(ctx, kCapacity * sizeof(shader::TextRect), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                  vk::MemoryUse::Upload, "text overlay")});
}

uint32_t TextOverlay::layout(const std::string& text, float scale, void* out, uint32_t capacity) {
  if (capacity < 2 || text.empty()) return 0;
  auto* rects = static_cast<shader::TextRect*>(out);
  // stb_easy_font writes 4 vertices of 16 bytes (x, y, z, rgba8) per quad, axis-aligned.
  std::vector<char> text0(text.begin(), text.end());
  text0.push_back('\0');
  // stb_easy_font draws a printable ASCII glyph with at most 11 segments (quads): room for 12 per character.
  std::vector<float> verts(std::min<size_t>(capacity - 1, 12 * text.size()) * 16);
  unsigned char white[4] = {255, 255, 255, 255};
  const int quads = stb_easy_font_print(kMargin, kMargin, text0.data(), white, verts.data(),
                                        int(verts.size() * sizeof(float)));
  const float w = float(stb_easy_font_width(text0.data())) + 2 * kMargin;
  const float h = float(stb_easy_font_height(text0.data())) + 2 * kMargin;
  rects[0] = {{0, 0, w * scale, h * scale}, {0.02f, 0.02f, 0.02f, 1.0f}};
  for (int q = 0; q < quads; ++q) {
    const float* v = &verts[size_t(q) * 16];  // corners 0 (top-left) and 2 (bottom-right)
    rects[q + 1] = {{v[0] * scale, v[1] * scale, v[8] * scale, v[9] * scale}, {1.0f, 1.0f, 1.0f, 1.0f}};
  }
  return uint32_t(quads) + 1;
}

const vk::Pipeline& TextOverlay::pipeline(VkFormat format) {
  auto it = pipelines_.find(format);
  if (it != pipelines_.end()) return it->second;
  vk::GraphicsDesc d;
  d.modules = {vk::loadShader("text.vert"), vk::loadShader("text.frag")};
  d.cullMode = VK_CULL_MODE_NONE;
  d.depthTest = d.depthWrite = false;
  d.colorFormats = {format};
  return pipelines_.emplace(format, vk::makeGraphicsPipeline(ctx_, d, {.pushDescriptorSets = {0}})).first->second;
}

void TextOverlay::record(VkCommandBuffer cb, uint32_t frame, const std::string& text, VkImage image,
                         VkImageView view, VkFormat format, VkExtent2D extent, VkImageLayout layout,
                         VkImageLayout finalLayout, float scale) {
  FrameText& ft = frames_.at(frame);
  if (ft.text != text || ft.scale != scale) {  // not in use: this frame slot's fence has signalled
    ft.count = TextOverlay::layout(text, scale, ft.rects.mapped(), kCapacity);
    ft.rects.flush();
    ft.text = text;
    ft.scale = scale;
  }
  const vk::Buffer& buf = ft.rects;
  const uint32_t count = ft.count;
  // Everything before wrote the image (post pass, copies): wait for all of it, keep its contents.
  vk::barrier(cb, {{image, layout, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                    VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                    VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, 0, 1}});
  if (count > 0) {
    const vk::Pipeline& p = pipeline(format);
    vk::beginColorRendering(cb, view, extent, VK_ATTACHMENT_LOAD_OP_LOAD);  // text over the frame
    p.bind(cb);
    vk::DescriptorWriter(ctx_, p.layout, 0, VK_NULL_HANDLE).buffer(0, buf.handle()).push(cb, p);
    p.push(cb, shader::TextPush{{2.0f / float(extent.width), 2.0f / float(extent.height)}});
    vkCmdDraw(cb, count * 6, 1, 0, 0);
    vkCmdEndRendering(cb);
  }
  const bool present = finalLayout == VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  vk::barrier(cb, {{image, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, finalLayout,
                    VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                    VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                    present ? VK_ACCESS_2_NONE : VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT, 0, 1}});
}

}  // namespace rtr::render
