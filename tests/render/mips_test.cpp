// Mip chains on the GPU against the float64 reference (src/core/mip_reference.hpp): every texel of every
// level within 1 LSB for the compute modes; the blit chain's difference is reported, not required.
#include <algorithm>
#include <cstring>
#include <random>
#include <sstream>

#include "core/mip_reference.hpp"
#include "render/mips.hpp"
#include "vk/commands.hpp"
#include "vk/context.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using render::MipMode;
using test::VulkanTest;

uint32_t texelBytes(VkFormat f) { return f == VK_FORMAT_R8_UNORM ? 1 : 4; }
TexelEncoding encodingOf(VkFormat f) { return f == VK_FORMAT_R8G8B8A8_SRGB ? TexelEncoding::Srgb : TexelEncoding::Unorm; }
VkDeviceSize align16(VkDeviceSize v) { return (v + 15) & ~VkDeviceSize(15); }

// Random bytes, or (binary) only 0 and 255: the hardest case for split boundary texels.
TexelData randomTexels(VkExtent2D e, VkFormat f, uint32_t seed, bool binary) {
  TexelData t{e.width, e.height, texelBytes(f), {}};
  t.texels.resize(size_t(e.width) * e.height * t.channels);
  std::mt19937 rng(seed);
  for (auto& b : t.texels) b = binary ? uint8_t(rng() & 1 ? 255 : 0) : uint8_t(rng() & 0xFF);
  return t;
}

class MipsTest : public VulkanTest {
 public:
  // Uploads level 0, generates the chain, reads every level back (bytes per level).
  std::vector<std::vector<uint8_t>> run(const TexelData& src, VkFormat format, MipMode mode) {
    const VkExtent2D extent{src.width, src.height};
    vk::Image image(*ctx, render::textureDesc(extent, format, "mip test texture"));
    const uint32_t levels = image.mipLevels();
    std::vector<VkDeviceSize> offsets;
    VkDeviceSize total = 0;
    for (uint32_t l = 0; l < levels; ++l) {
      offsets.push_back(total);
      total = align16(total + VkDeviceSize(mipLevelSize(src.width, l)) * mipLevelSize(src.height, l) * src.channels);
    }
    vk::Buffer upload(*ctx, src.texels.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUse::Upload);
    std::memcpy(upload.mapped(), src.texels.data(), src.texels.size());
    upload.flush();
    vk::Buffer readback(*ctx, total, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback);
    render::MipGenerator gen(*ctx);
    render::MipViews views;
    vk::submitAndWait(*ctx, [&](VkCommandBuffer cb) {
      vk::barrier(cb, {{image.handle(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                        VK_PIPELINE_STAGE_2_NONE, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE,
                        VK_ACCESS_2_TRANSFER_WRITE_BIT, 0, 1}});
      VkBufferImageCopy c{};
      c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      c.imageExtent = {extent.width, extent.height, 1};
      vkCmdCopyBufferToImage(cb, upload.handle(), image.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &c);
      views = gen.record(cb, image, mode);
      // The contract leaves every level readable by shaders; reading back needs transfer access too.
      vk::barrier(cb, {{image.handle(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                        VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                        VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE, VK_ACCESS_2_TRANSFER_READ_BIT}});
      std::vector<VkBufferImageCopy> copies;
      for (uint32_t l = 0; l < levels; ++l) {
        VkBufferImageCopy r{};
        r.bufferOffset = offsets[l];
        r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, l, 0, 1};
        r.imageExtent = {mipLevelSize(extent.width, l), mipLevelSize(extent.height, l), 1};
        copies.push_back(r);
      }
      vkCmdCopyImageToBuffer(cb, image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.handle(),
                             uint32_t(copies.size()), copies.data());
      vk::memoryBarrier(cb, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                        VK_ACCESS_2_HOST_READ_BIT);
    });
    readback.invalidate();
    std::vector<std::vector<uint8_t>> out;
    for (uint32_t l = 0; l < levels; ++l) {
      const uint8_t* p = static_cast<const uint8_t*>(readback.mapped()) + offsets[l];
      out.emplace_back(p, p + size_t(mipLevelSize(src.width, l)) * mipLevelSize(src.height, l) * src.channels);
    }
    return out;
  }
};

// Largest byte difference over all levels >= 1, and where it is.
struct MaxDiff {
  int value = 0;
  std::string where;
};
MaxDiff compare(const std::vector<std::vector<uint8_t>>& gpu, const MipChain& ref) {
  MaxDiff m;
  for (uint32_t l = 1; l < ref.levels.size(); ++l) {
    const std::vector<uint8_t> want = quantizeMipLevel(ref, l);
    for (size_t i = 0; i < want.size(); ++i) {
      const int d = std::abs(int(gpu[l][i]) - int(want[i]));
      if (d > m.value) {
        std::ostringstream s;
        const uint32_t w = ref.levels[l].width, texel = uint32_t(i / ref.channels);
        s << "level " << l << " texel (" << texel % w << ", " << texel / w << ") channel " << i % ref.channels
          << ": gpu " << int(gpu[l][i]) << " reference " << int(want[i]);
        m = {d, s.str()};
      }
    }
  }
  return m;
}

const VkExtent2D kSizes[] = {{1, 1},  {1, 37},   {37, 1},   {64, 64},  {63, 63},
                             {65, 65}, {256, 256}, {255, 129}, {200, 120}, {257, 5}};
const VkFormat kFormats[] = {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R8_UNORM};

std::string label(VkExtent2D e, VkFormat f, MipMode m) {
  std::ostringstream s;
  s << e.width << "x" << e.height << " "
    << (f == VK_FORMAT_R8G8B8A8_SRGB ? "srgb" : f == VK_FORMAT_R8_UNORM ? "r8" : "unorm") << " " << render::toString(m);
  return s.str();
}

void expectWithinOneLsb(MipsTest& t, MipMode mode) {
  uint32_t seed = 1;
  for (VkExtent2D e : kSizes)
    for (VkFormat f : kFormats)
      for (bool binary : {false, true}) {
        const TexelData src = randomTexels(e, f, seed++, binary);
        const auto gpu = t.run(src, f, mode);
        ASSERT_EQ(gpu[0], src.texels) << "level 0 changed, " << label(e, f, mode);
        const MaxDiff d = compare(gpu, buildMipReference(src, encodingOf(f), MipSource::PreviousLevel));
        EXPECT_LE(d.value, 1) << label(e, f, mode) << (binary ? " binary" : " random") << ", worst at " << d.where;
      }
}

TEST_F(MipsTest, MultiLevelComputeWithinOneLsbOfReference) { expectWithinOneLsb(*this, MipMode::Compute); }
TEST_F(MipsTest, PerLevelComputeWithinOneLsbOfReference) { expectWithinOneLsb(*this, MipMode::ComputePerLevel); }

// Blits filter however the driver does (bilinear at odd sizes, own rounding): report the difference;
// assert only that power-of-two sizes, where a blit is a 2x2 average, are roughly right.
TEST_F(MipsTest, BlitChainDifferenceIsReported) {
  uint32_t seed = 100;
  for (VkExtent2D e : kSizes)
    for (VkFormat f : kFormats) {
      const TexelData src = randomTexels(e, f, seed++, false);
      const auto gpu = run(src, f, MipMode::Blit);
      const MaxDiff d = compare(gpu, buildMipReference(src, encodingOf(f), MipSource::PreviousLevel));
      const std::string name = label(e, f, MipMode::Blit);
      RecordProperty(name, d.value);
      std::printf("max |blit - reference| %s: %d LSB%s%s\n", name.c_str(), d.value, d.value ? " at " : "", d.where.c_str());
      const bool pot = (e.width & (e.width - 1)) == 0 && (e.height & (e.height - 1)) == 0;
      // A wrong level or a broken readback is off by ~100; drivers round their blits differently.
      if (pot) EXPECT_LE(d.value, 8) << name << ", worst at " << d.where;
    }
}

TEST(MipPlan, MultiLevelDispatchesWriteSixLevelsForPowerOfTwo) {
  const auto plan = render::planMipDispatches({1024, 1024}, MipMode::Compute);
  ASSERT_EQ(plan.size(), 2u);
  EXPECT_EQ(plan[0].levels, 6u);
  EXPECT_EQ(plan[0].groups.width, 16u);
  EXPECT_EQ(plan[1].srcLevel, 6u);
  EXPECT_EQ(plan[1].levels, 4u);
  const auto npot = render::planMipDispatches({1000, 600}, MipMode::Compute);
  uint32_t written = 0;
  for (const auto& d : npot) {
    EXPECT_EQ(d.srcLevel, written);
    written += d.levels;
  }
  EXPECT_EQ(written, render::mipLevelCount({1000, 600}) - 1);
  EXPECT_LE(npot.size(), 3u);
  EXPECT_EQ(render::planMipDispatches({1000, 600}, MipMode::ComputePerLevel).size(), written);
}

TEST(MipPlan, TextureDescHasTheFullChain) {
  EXPECT_EQ(render::textureDesc({1, 1}, VK_FORMAT_R8_UNORM).mipLevels, 1u);
  EXPECT_EQ(render::textureDesc({1000, 600}, VK_FORMAT_R8G8B8A8_UNORM).mipLevels, 10u);
  const vk::ImageDesc s = render::textureDesc({4, 4}, VK_FORMAT_R8G8B8A8_SRGB);
  EXPECT_TRUE(s.flags & VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT);
  EXPECT_FALSE(s.viewUsage & VK_IMAGE_USAGE_STORAGE_BIT);
}

}  // namespace
}  // namespace rtr
