#include "render/text_overlay.hpp"

#include <algorithm>
#include <cstring>
#include <vector>

#include <stb_easy_font.h>

#include "text.h"
#include "vk/commands.hpp"
#include "vk/context.hpp"

namespace rtr::render {
namespace {

constexpr float kMargin = 4.0f;        // font units of backdrop around the text

}  // namespace

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

void TextOverlay::record(vk::Frame& frame, const std::string& text, vk::TrackedImage image, VkImageView view,
                         VkFormat format, VkExtent2D extent, float scale) {
  if (text != text_ || scale != scale_ || rects_.empty()) {
    rects_.resize(kCapacity * sizeof(shader::TextRect));
    rects_.resize(TextOverlay::layout(text, scale, rects_.data(), kCapacity) * sizeof(shader::TextRect));
    text_ = text;
    scale_ = scale;
  }
  const uint32_t count = uint32_t(rects_.size() / sizeof(shader::TextRect));
  // Its contents are kept: the tracker waits for whatever wrote the image last (post pass, copies).
  vk::require(frame.cb, image, vk::Use::ColorAttachment, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT);
  if (count == 0) return;
  // This frame's arena: an earlier frame still in flight keeps its own rectangles.
  const vk::UploadArena::Slice slice =
      frame.upload(rects_.size(), ctx_.properties().limits.minStorageBufferOffsetAlignment);
  std::memcpy(slice.data, rects_.data(), rects_.size());
  const vk::Pipeline& p = pipeline(format);
  vk::beginColorRendering(frame.cb, view, extent, VK_ATTACHMENT_LOAD_OP_LOAD);  // text over the frame
  p.bind(frame.cb);
  vk::DescriptorWriter(ctx_, p.layout, 0, VK_NULL_HANDLE)
      .buffer(0, slice.buffer, slice.offset, rects_.size())
      .push(frame.cb, p);
  p.push(frame.cb, shader::TextPush{{2.0f / float(extent.width), 2.0f / float(extent.height)}});
  vkCmdDraw(frame.cb, count * 6, 1, 0, 0);
  vkCmdEndRendering(frame.cb);
}

}  // namespace rtr::render
