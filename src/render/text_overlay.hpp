#pragma once
// Text drawn over a finished frame: the viewer's timing overlay (F1/H). stb_easy_font turns the lines into
// rectangles, a small graphics pipeline draws them over a dark backdrop. Recorded after the frame (and
// after any screenshot copy), so a screenshot never contains it.
#include <map>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "vk/frame_ring.hpp"
#include "vk/pipeline.hpp"
#include "vk/resources.hpp"

namespace rtr::render {

class TextOverlay {
 public:
  // Pipelines are made per target format on first use.
  explicit TextOverlay(const vk::Context& ctx) : ctx_(ctx) {}

  // Draws `text` (lines separated by '\n') at the top-left of `image` (required as a colour attachment,
  // its contents kept; left so). The rectangles go through the frame's upload arena. Text beyond
  // kCapacity rectangles is cut off. `scale`: pixels per font unit.
  void record(vk::Frame& frame, const std::string& text, vk::TrackedImage image, VkImageView view, VkFormat format,
              VkExtent2D extent, float scale = 2.0f);
  static constexpr uint32_t kCapacity = 16384;  // rectangles per frame: about 2,500 characters

  // The rectangles `text` becomes (backdrop first): exposed for the test of the layout.
  static uint32_t layout(const std::string& text, float scale, void* rects, uint32_t capacity);

 private:
  const vk::Pipeline& pipeline(VkFormat format);
  const vk::Context& ctx_;
  // The last layout, kept so that an unchanged text is only copied, not laid out again.
  std::string text_;
  float scale_ = 0;
  std::vector<uint8_t> rects_;
  std::map<VkFormat, vk::Pipeline> pipelines_;
};

}  // namespace rtr::render
