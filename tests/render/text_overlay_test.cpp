// The viewer's text overlay: draws white glyphs on a dark backdrop at the top-left, keeps every other
// pixel of the frame, and cuts text off at the buffer's capacity instead of overrunning it.
#include <cstring>

#include "render/text_overlay.hpp"
#include "vk/frame_ring.hpp"
#include "text.h"
#include "vk/commands.hpp"
#include "vk/context.hpp"
#include "vk/resources.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using test::VulkanTest;

TEST(TextOverlayLayout, BackdropEnclosesEveryGlyph) {
  std::vector<shader::TextRect> rects(4096);
  const uint32_t n = render::TextOverlay::layout("GPU scene 1.234 ms\nmode: shaded", 2.0f, rects.data(), 4096);
  ASSERT_GT(n, 20u);  // the backdrop and many segments
  const glm::vec4 b = rects[0].rect;
  for (uint32_t i = 1; i < n; ++i) {
    const glm::vec4 r = rects[i].rect;
    EXPECT_LT(r.x, r.z);
    EXPECT_LT(r.y, r.w);
    EXPECT_GE(r.x, b.x);
    EXPECT_GE(r.y, b.y);
    EXPECT_LE(r.z, b.z);
    EXPECT_LE(r.w, b.w);
  }
  // A second line sits below the first: some glyph starts below the first line's height.
  float maxY = 0;
  for (uint32_t i = 1; i < n; ++i) maxY = std::max(maxY, rects[i].rect.y);
  EXPECT_GT(maxY, 2.0f * 12.0f);
}

TEST(TextOverlayLayout, CapacityIsRespected) {
  std::vector<shader::TextRect> rects(64);
  const std::string longText(500, '8');
  EXPECT_LE(render::TextOverlay::layout(longText, 1.0f, rects.data(), 64), 64u);
  EXPECT_EQ(render::TextOverlay::layout("", 1.0f, rects.data(), 64), 0u);
}

class TextOverlayTest : public VulkanTest {};

TEST_F(TextOverlayTest, DrawsTextOverTheFrameAndKeepsTheRest) {
  const VkExtent2D e{320, 96};
  const VkFormat format = VK_FORMAT_B8G8R8A8_UNORM;  // a typical swapchain format
  vk::Image img(*ctx, {e, format, 1, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                                         VK_IMAGE_USAGE_TRANSFER_DST_BIT, 0, 0, "frame"});
  const size_t bytes = size_t(e.width) * e.height * 4;
  vk::Buffer readback(*ctx, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback);
  render::TextOverlay overlay(*ctx);
  vk::FrameRing ring(*ctx, 1);
  const std::string text = "scene 1.234 ms";
  {
    vk::Frame& f = ring.begin();
    VkCommandBuffer cb = f.cb;
    vk::require(cb, img.tracked(), vk::Use::CopyDst, VK_PIPELINE_STAGE_2_CLEAR_BIT, true);
    const VkClearColorValue grey{{0.5f, 0.5f, 0.5f, 1.0f}};
    const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdClearColorImage(cb, img.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &grey, 1, &range);
    overlay.record(f, text, img.tracked(), img.view(), format, e);
    vk::require(cb, img.tracked(), vk::Use::CopySrc, VK_PIPELINE_STAGE_2_COPY_BIT);
    vk::copyImageToHost(cb, img.handle(), e, readback.handle());
    ring.submit(f);
    ring.waitIdle();
  }
  readback.invalidate();
  const uint8_t* px = static_cast<const uint8_t*>(readback.mapped());

  std::vector<shader::TextRect> rects(4096);
  ASSERT_GT(render::TextOverlay::layout(text, 2.0f, rects.data(), 4096), 1u);
  const glm::vec4 b = rects[0].rect;
  size_t white = 0, dark = 0, greyInside = 0, changedOutside = 0;
  for (uint32_t y = 0; y < e.height; ++y)
    for (uint32_t x = 0; x < e.width; ++x) {
      const uint8_t* p = px + (size_t(y) * e.width + x) * 4;
      const bool inside = x + 0.5f > b.x && x + 0.5f < b.z && y + 0.5f > b.y && y + 0.5f < b.w;
      const bool isGrey = p[0] >= 127 && p[0] <= 128 && p[1] >= 127 && p[1] <= 128;
      if (!inside) changedOutside += !isGrey;
      else if (p[0] == 255 && p[1] == 255 && p[2] == 255) ++white;
      else if (p[0] < 10 && p[1] < 10 && p[2] < 10) ++dark;
      else ++greyInside;
    }
  EXPECT_EQ(changedOutside, 0u) << "pixels outside the backdrop changed";
  EXPECT_EQ(greyInside, 0u) << "backdrop pixels not covered";
  EXPECT_GT(white, 100u);
  EXPECT_GT(dark, white);  // glyph strokes are thin
}

}  // namespace
}  // namespace rtr
