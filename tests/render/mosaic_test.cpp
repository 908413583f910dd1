// The mosaic pass: compute and graphics bit-identical, both equal to the CPU rule (each block filled with
// its chosen pixel), Off equal to a plain sRGB encode of the input.
#include <cmath>
#include <cstring>
#include <random>

#include <glm/gtc/packing.hpp>

#include "core/error.hpp"
#include "render/post.hpp"
#include "vk/commands.hpp"
#include "vk/context.hpp"
#include "vk/resources.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using render::MosaicMode;
using test::VulkanTest;

uint8_t encodeSrgb8(double linear) {
  const double c = std::clamp(linear, 0.0, 1.0);
  const double s = c <= 0.0031308 ? c * 12.92 : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
  return uint8_t(std::floor(s * 255.0 + 0.5));
}

class MosaicTest : public VulkanTest {
 protected:
  void TearDown() override {
    input.reset();  // before the device goes
    VulkanTest::TearDown();
  }

  // Random linear colour in [0, 1.25) (some above 1: the encode must clamp) as RGBA16F.
  void makeInput(VkExtent2D e, uint32_t seed) {
    extent = e;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.25f);
    halfs.resize(size_t(e.width) * e.height * 4);
    for (auto& h : halfs) h = glm::packHalf1x16(u(rng));
    input = vk::Image(*ctx, {e, VK_FORMAT_R16G16B16A16_SFLOAT, 1, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, 0,
                             0, "scene colour"});
    vk::Buffer upload(*ctx, halfs.size() * 2, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUse::Upload);
    std::memcpy(upload.mapped(), halfs.data(), halfs.size() * 2);
    upload.flush();
    vk::submitAndWait(*ctx, [&](VkCommandBuffer cb) {
      vk::require(cb, input.tracked(), vk::Use::CopyDst, VK_PIPELINE_STAGE_2_COPY_BIT, true);
      VkBufferImageCopy c{};
      c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      c.imageExtent = {e.width, e.height, 1};
      vkCmdCopyBufferToImage(cb, upload.handle(), input.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &c);
    });
  }

  // Runs the pass into a fresh output image and reads it back (4 bytes per pixel, in memory order).
  std::vector<uint8_t> run(render::MosaicPass& pass, MosaicMode mode, VkFormat format = VK_FORMAT_R8G8B8A8_UNORM) {
    vk::Image out(*ctx, {extent, format, 1,
                         VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, 0, 0,
                         "post output"});
    const size_t bytes = size_t(extent.width) * extent.height * 4;
    vk::Buffer readback(*ctx, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback);
    vk::submitAndWait(*ctx, [&](VkCommandBuffer cb) {
      pass.record(cb, input.tracked(), input.view(), out.tracked(), out.view(), format, extent, mode);
      vk::require(cb, out.tracked(), vk::Use::CopySrc, VK_PIPELINE_STAGE_2_COPY_BIT);
      vk::copyImageToHost(cb, out.handle(), extent, readback.handle());
    });
    readback.invalidate();
    const uint8_t* p = static_cast<const uint8_t*>(readback.mapped());
    return {p, p + bytes};
  }

  // Checks a mosaic result block by block against `plain` (the Off output): every pixel of a block
  // equals plain at the block's chosen pixel, the centre clamped into the image (and so into the block).
  void expectBlocks(const std::vector<uint8_t>& mosaic, const std::vector<uint8_t>& plain, VkExtent2D block) {
    const uint32_t w = extent.width, h = extent.height;
    for (uint32_t by = 0; by < h; by += block.height)
      for (uint32_t bx = 0; bx < w; bx += block.width) {
        const uint32_t cx = std::min(bx + block.width / 2, w - 1), cy = std::min(by + block.height / 2, h - 1);
        ASSERT_TRUE(cx >= bx && cy >= by);
        for (uint32_t y = by; y < std::min(by + block.height, h); ++y)
          for (uint32_t x = bx; x < std::min(bx + block.width, w); ++x)
            ASSERT_EQ(0, std::memcmp(&mosaic[(y * w + x) * 4], &plain[(cy * w + cx) * 4], 4))
                << "pixel (" << x << ", " << y << ") of the block at (" << bx << ", " << by << ")";
      }
  }

  // Off output against a float64 sRGB encode of the input (alpha is written as 1).
  void expectPlainEncode(const std::vector<uint8_t>& plain) {
    int worst = 0;
    for (size_t i = 0; i < plain.size(); ++i) {
      const uint8_t want = i % 4 == 3 ? 255 : encodeSrgb8(glm::unpackHalf1x16(halfs[i]));
      worst = std::max(worst, std::abs(int(plain[i]) - int(want)));
    }
    EXPECT_LE(worst, 1) << "sRGB encode of the plain copy";
  }

  VkExtent2D extent{};
  std::vector<uint16_t> halfs;
  vk::Image input;
};

// 701x41 spans several workgroups in both directions, with partial tiles and blocks.
TEST_F(MosaicTest, ComputeAndGraphicsAreBitIdenticalAndFollowTheRule) {
  render::MosaicPass pass(*ctx);
  uint32_t seed = 7;
  for (VkExtent2D e : {VkExtent2D{64, 48}, {67, 50}, {5, 3}, {1, 1}, {4, 2}, {13, 1}, {701, 41}}) {
    SCOPED_TRACE(testing::Message() << e.width << "x" << e.height);
    makeInput(e, seed++);
    const auto compute = run(pass, MosaicMode::Compute);
    const auto graphics = run(pass, MosaicMode::Graphics);
    const auto plain = run(pass, MosaicMode::Off);
    EXPECT_TRUE(compute == graphics) << "compute and graphics differ";
    expectPlainEncode(plain);
    expectBlocks(compute, plain, {5, 3});
    expectBlocks(graphics, plain, {5, 3});
  }
}

TEST_F(MosaicTest, OtherBlockSizes) {
  render::MosaicPass pass(*ctx);
  makeInput({40, 23}, 99);
  const auto plain = run(pass, MosaicMode::Off);
  for (VkExtent2D b : {VkExtent2D{1, 1}, {2, 2}, {8, 4}, {3, 7}, {64, 64}}) {
    SCOPED_TRACE(testing::Message() << "block " << b.width << "x" << b.height);
    pass.setBlock(b);
    const auto compute = run(pass, MosaicMode::Compute);
    EXPECT_TRUE(compute == run(pass, MosaicMode::Graphics));
    expectBlocks(compute, plain, b);
  }
  EXPECT_THROW(pass.setBlock({0, 3}), Error);
}

// The swapchain's usual format: the storage write needs no format qualifier, components stay R, G, B.
TEST_F(MosaicTest, WritesBgraOutputs) {
  VkFormatProperties fp;
  vkGetPhysicalDeviceFormatProperties(ctx->physicalDevice(), VK_FORMAT_B8G8R8A8_UNORM, &fp);
  if (!(fp.optimalTilingFeatures & VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT)) GTEST_SKIP() << "no BGRA storage images";
  render::MosaicPass pass(*ctx);
  makeInput({21, 9}, 5);
  const auto rgba = run(pass, MosaicMode::Compute);
  const auto bgra = run(pass, MosaicMode::Compute, VK_FORMAT_B8G8R8A8_UNORM);
  const auto bgraGraphics = run(pass, MosaicMode::Graphics, VK_FORMAT_B8G8R8A8_UNORM);
  EXPECT_TRUE(bgra == bgraGraphics);
  for (size_t i = 0; i < rgba.size(); i += 4) {
    ASSERT_EQ(rgba[i], bgra[i + 2]);
    ASSERT_EQ(rgba[i + 2], bgra[i]);
    ASSERT_EQ(rgba[i + 1], bgra[i + 1]);
  }
}

}  // namespace
}  // namespace rtr
