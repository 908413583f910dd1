// The tracer overlay's upload with frames in flight: each frame must show the CPU image as it was when
// that frame was recorded, even when a later frame uploads a newer image before the earlier one ran.
#include <algorithm>

#include <gtest/gtest.h>

#include "test_paths.hpp"

#include "scene/load.hpp"
#include "trace_overlay.hpp"
#include "vk/commands.hpp"
#include "vk/frame_ring.hpp"
#include "vk/image_state.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

constexpr uint32_t kW = 64, kH = 48;

class TraceOverlayTest : public test::VulkanTest {};

TEST_F(TraceOverlayTest, EachFrameInFlightShowsItsOwnUpload) {
  const Scene scene = loadScene(test::sourceDir() / "assets-src/rt/cornell_box.obj");
  view::TraceOverlay overlay(*ctx, scene);
  constexpr uint32_t kFrames = 3;
  vk::FrameRing ring(*ctx, kFrames);
  struct Shown {
    vk::Image image;
    vk::Buffer readback;
    ImageRGBA8 expected;
    vk::Frame* frame;
  };
  std::vector<Shown> shown(kFrames);
  const trace::Shading shadings[kFrames] = {trace::Shading::Phong, trace::Shading::Normals, trace::Shading::Pbr};
  // Record every frame before submitting any: the earliest frames' copies run only after the later
  // frames have uploaded their images (the worst case of a delayed submit).
  for (uint32_t i = 0; i < kFrames; ++i) {
    trace::TraceSettings ts;
    ts.width = kW;
    ts.height = kH;
    ts.shading = shadings[i];
    ts.tileSize = 16;
    overlay.start(ts);
    overlay.wait();
    Shown& s = shown[i];
    s.expected = overlay.cpuImage();
    s.image =
        vk::Image(*ctx, {{kW, kH},
                         VK_FORMAT_R8G8B8A8_UNORM,
                         1,
                         VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT,
                         0,
                         0,
                         "shown"});
    s.readback = vk::Buffer(*ctx, VkDeviceSize(kW) * kH * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback);
    s.frame = &ring.begin();
    VkCommandBuffer cb = s.frame->cb;
    vk::barrier(cb, {{s.image.handle(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE,
                      VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE, VK_ACCESS_2_TRANSFER_WRITE_BIT}});
    overlay.recordCopy(*s.frame, s.image.handle(), VK_FORMAT_R8G8B8A8_UNORM, {kW, kH});
    vk::barrier(cb, {{s.image.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                      VK_PIPELINE_STAGE_2_COPY_BIT, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                      VK_ACCESS_2_TRANSFER_READ_BIT}});
    vk::copyImageToHost(cb, s.image.handle(), {kW, kH}, s.readback.handle());
  }
  for (Shown& s : shown) ring.submit(*s.frame);
  ring.waitIdle();
  for (uint32_t i = 0; i < kFrames; ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    if (i > 0) { ASSERT_NE(shown[i].expected.pixels, shown[i - 1].expected.pixels) << "the test needs differing images"; }
    shown[i].readback.invalidate();
    const auto* got = static_cast<const uint8_t*>(shown[i].readback.mapped());
    // Tile by tile, so that a failure says where.
    for (uint32_t ty = 0; ty < kH; ty += 16) {
      for (uint32_t tx = 0; tx < kW; tx += 16) {
        size_t wrong = 0;
        for (uint32_t y = ty; y < ty + 16; ++y)
          for (uint32_t x = tx; x < tx + 16; ++x)
            for (int c = 0; c < 4; ++c) {
              const size_t k = (size_t(y) * kW + x) * 4 + c;
              wrong += got[k] != shown[i].expected.pixels[k];
            }
        EXPECT_EQ(wrong, 0u) << "tile at " << tx << "," << ty;
      }
    }
  }
}

// A finished trace is uploaded once: later frames copy it on the GPU and take no upload bytes, and still
// show it whole.
TEST_F(TraceOverlayTest, AFinishedTraceIsUploadedOnce) {
  const Scene scene = loadScene(test::sourceDir() / "assets-src/rt/cornell_box.obj");
  view::TraceOverlay overlay(*ctx, scene);
  trace::TraceSettings ts;
  ts.width = kW;
  ts.height = kH;
  overlay.start(ts);
  overlay.wait();
  const ImageRGBA8 expected = overlay.cpuImage();
  vk::FrameRing ring(*ctx, 1);
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    vk::Image target(*ctx, {{kW, kH},
                            VK_FORMAT_R8G8B8A8_UNORM,
                            1,
                            VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                            0,
                            0,
                            "target"});
    vk::Buffer readback(*ctx, VkDeviceSize(kW) * kH * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback);
    vk::Frame& f = ring.begin();
    vk::require(f.cb, target.tracked(), vk::Use::CopyDst, VK_PIPELINE_STAGE_2_COPY_BIT, true);
    overlay.recordCopy(f, target.handle(), VK_FORMAT_R8G8B8A8_UNORM, {kW, kH});
    if (i == 0) {
      EXPECT_GE(f.arena.used(), expected.pixels.size());
    } else {
      EXPECT_EQ(f.arena.used(), 0u) << "an unchanged trace was uploaded again";
    }
    vk::require(f.cb, target.tracked(), vk::Use::CopySrc, VK_PIPELINE_STAGE_2_COPY_BIT);
    vk::copyImageToHost(f.cb, target.handle(), {kW, kH}, readback.handle());
    ring.submit(f);
    ring.waitIdle();
    readback.invalidate();
    const auto* got = static_cast<const uint8_t*>(readback.mapped());
    EXPECT_TRUE(std::equal(expected.pixels.begin(), expected.pixels.end(), got));
  }
}

}  // namespace
}  // namespace rtr
