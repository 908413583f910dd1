#pragma once
// Text drawn over a finished frame: the viewer's timing overlay (F1/H). stb_easy_font turns the lines into
// rectangles, a small graphics pipeline draws them over a dark backdrop. Recorded after the frame (and
// after any screenshot copy), so a screenshot never contains it.
#include <map>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "vk/pipeline.hpp"
#include "vk/resources.hpp"

namespace rtr::render {

class TextOverlay {
 public:
  // One rectangle buffer per frame in flight; pipelines are made per target format on first use.
  TextOverlay(const vk::Context& ctx, uint32_t framesInFlight);

  // Draws `text` (lines separated by '\n') at the top-left of `image`, which is in `layout` and is left in
  // `finalLayout`. Text beyond the buffer's capacity is cut off. `scale`: pixels per font unit.
  void record(VkCommandBuffer cb, uint32_t frame, const std::string& text, VkImage image, VkImageView view,
              VkFormat format, VkExtent2D extent, VkImageLayout layout, VkImageLayout finalLayout, float scale = 2.0f);

  // The rectangles `text` becomes (backdrop first): exposed for the test of the layout.
  static uint32_t layout(const std::string& text, float scale, void* rects, uint32_t capacity);

 private:
  const vk::Pipeline& pipeline(VkFormat format);
  const vk::Context& ctx_;
  struct FrameText {
    vk::Buffer rects;
    std::string text;  // what `rects` holds: laid out again only when the text changes
    float scale = 0;
    uint32_t count = 0;
  };
  std::vector<FrameText> frames_;
  std::map<VkFormat, vk::Pipeline> pipelines_;
};

}  // namespace rtr::render
