#include "core/mip_reference.hpp"

#include <cmath>
#include <random>
#include <utility>

#include <gtest/gtest.h>

#include "core/error.hpp"

namespace rtr {
namespace {

TexelData noise(uint32_t w, uint32_t h, uint32_t ch, uint32_t seed) {
  std::mt19937 rng(seed);
  TexelData t{w, h, ch, std::vector<uint8_t>(size_t(w) * h * ch)};
  for (auto& b : t.texels) b = uint8_t(rng() & 255);
  return t;
}

double channelMean(const MipLevel& level, uint32_t channels, uint32_t c) {
  double s = 0;
  for (size_t i = c; i < level.texels.size(); i += channels) s += level.texels[i];
  return s / (double(level.width) * level.height);
}

TEST(MipReference, VulkanLevelSizes) {
  const std::pair<uint32_t, uint32_t> sizes[] = {{1, 1}, {1, 7}, {8, 8}, {7, 7}, {9, 9}, {16, 5}, {5, 16}, {1000, 3}};
  for (auto [w, h] : sizes) {
    MipChain chain = buildMipReference(noise(w, h, 1, 1), TexelEncoding::Unorm);
    ASSERT_EQ(chain.levels.size(), mipLevelCount(w, h));
    for (uint32_t k = 0; k < chain.levels.size(); ++k) {
      EXPECT_EQ(chain.levels[k].width, std::max(1u, w >> k));
      EXPECT_EQ(chain.levels[k].height, std::max(1u, h >> k));
    }
    EXPECT_EQ(chain.levels.back().width * chain.levels.back().height, 1u);
  }
  EXPECT_EQ(mipLevelCount(1, 1), 1u);
  EXPECT_EQ(mipLevelCount(1, 7), 3u);   // 7, 3, 1
  EXPECT_EQ(mipLevelCount(9, 9), 4u);   // 9, 4, 2, 1
  EXPECT_EQ(mipLevelCount(16, 5), 5u);  // 16x5, 8x2, 4x1, 2x1, 1x1
}

TEST(MipReference, EveryLevelKeepsTheLinearMean) {
  const std::pair<uint32_t, uint32_t> sizes[] = {{1, 1}, {1, 13}, {13, 1}, {32, 32}, {31, 31}, {33, 33}, {37, 10}, {11, 64}};
  for (auto [w, h] : sizes)
    for (uint32_t ch = 1; ch <= 4; ++ch)
      for (TexelEncoding enc : {TexelEncoding::Unorm, TexelEncoding::Srgb})
        for (MipSource src : {MipSource::Level0, MipSource::PreviousLevel}) {
          MipChain chain = buildMipReference(noise(w, h, ch, w * 131 + h * 7 + ch), enc, src);
          for (uint32_t c = 0; c < ch; ++c) {
            double m0 = channelMean(chain.levels[0], ch, c);
            for (const MipLevel& level : chain.levels)
              EXPECT_NEAR(channelMean(level, ch, c), m0, 1e-12) << w << "x" << h << " ch " << c;
          }
        }
}

TEST(MipReference, HandCheckedValues) {
  // 2x2 -> 1x1: the plain average.
  MipChain a = buildMipReference(TexelData{2, 2, 1, {0, 255, 255, 255}}, TexelEncoding::Unorm);
  EXPECT_DOUBLE_EQ(a.levels[1].texels[0], 0.75);
  // 5x1 -> 2x1: each destination texel covers 2.5 source texels, the middle one split in half.
  // Values 0, .2, .4, .6, .8: (0 + .2 + .5*.4)/2.5 = .16 and (.5*.4 + .6 + .8)/2.5 = .64; then 1x1 = .4.
  MipChain b = buildMipReference(TexelData{5, 1, 1, {0, 51, 102, 153, 204}}, TexelEncoding::Unorm);
  ASSERT_EQ(b.levels[1].width, 2u);
  EXPECT_NEAR(b.levels[1].texels[0], 0.16, 1e-15);
  EXPECT_NEAR(b.levels[1].texels[1], 0.64, 1e-15);
  EXPECT_NEAR(b.levels[2].texels[0], 0.4, 1e-15);
  // The same along y, and 3x3 -> 1x1 is the mean of all nine texels.
  MipChain c = buildMipReference(TexelData{1, 5, 1, {0, 51, 102, 153, 204}}, TexelEncoding::Unorm);
  EXPECT_NEAR(c.levels[1].texels[1], 0.64, 1e-15);
  MipChain d = buildMipReference(TexelData{3, 3, 1, {0, 0, 0, 0, 255, 0, 0, 0, 0}}, TexelEncoding::Unorm);
  EXPECT_NEAR(d.levels[1].texels[0], 1.0 / 9, 1e-15);
  // 3x2 -> 1x1: x weights 1/3 each, y weights 1/2 each.
  MipChain e = buildMipReference(TexelData{3, 2, 1, {0, 0, 255, 51, 51, 51}}, TexelEncoding::Unorm);
  ASSERT_EQ(e.levels[1].height, 1u);
  EXPECT_NEAR(e.levels[1].texels[0], (1.0 / 3 + 0.2) / 2, 1e-15);
}

TEST(MipReference, SrgbAveragesInLinearAndAlphaStaysLinear) {
  // Black and white average to linear 0.5, which is sRGB byte 188 (0.7354 * 255 = 187.5...), not 128.
  MipChain rgba = buildMipReference(TexelData{2, 1, 4, {0, 0, 0, 0, 255, 255, 255, 255}}, TexelEncoding::Srgb);
  EXPECT_DOUBLE_EQ(rgba.levels[1].texels[0], 0.5);
  EXPECT_DOUBLE_EQ(rgba.levels[1].texels[3], 0.5);
  EXPECT_EQ(quantizeMipLevel(rgba, 1), (std::vector<uint8_t>{188, 188, 188, 128}));
  MipChain unorm = buildMipReference(TexelData{2, 1, 4, {0, 0, 0, 0, 255, 255, 255, 255}}, TexelEncoding::Unorm);
  EXPECT_EQ(quantizeMipLevel(unorm, 1), (std::vector<uint8_t>{128, 128, 128, 128}));
  // A 2-channel sRGB image (R8G8_SRGB) has no alpha: both channels are sRGB.
  MipChain rg = buildMipReference(TexelData{2, 1, 2, {0, 0, 255, 255}}, TexelEncoding::Srgb);
  EXPECT_EQ(quantizeMipLevel(rg, 1), (std::vector<uint8_t>{188, 188}));
  // Level 0 round-trips every byte through decode + encode.
  TexelData all{256, 1, 3, {}};
  for (int i = 0; i < 256; ++i) all.texels.insert(all.texels.end(), {uint8_t(i), uint8_t(i), uint8_t(255 - i)});
  MipChain chain = buildMipReference(all, TexelEncoding::Srgb);
  EXPECT_EQ(quantizeMipLevel(chain, 0), all.texels);
}

TEST(MipReference, SourceChoiceMattersOnlyForOddSizes) {
  // Power-of-two: cascading in double is exactly the box over level 0.
  TexelData pot = noise(32, 16, 4, 5);
  MipChain direct = buildMipReference(pot, TexelEncoding::Srgb, MipSource::Level0);
  MipChain cascade = buildMipReference(pot, TexelEncoding::Srgb, MipSource::PreviousLevel);
  for (size_t k = 0; k < direct.levels.size(); ++k)
    for (size_t i = 0; i < direct.levels[k].texels.size(); ++i)
      ASSERT_NEAR(direct.levels[k].texels[i], cascade.levels[k].texels[i], 1e-14);
  // 11 -> 5 -> 2: level 2 from level 0 covers source [0, 5.5); from level 1 it takes level-1 texel 2
  // (source [4.4, 6.6)) at half weight, so it also reads source texel 6.
  TexelData odd{11, 1, 1, {0, 0, 0, 0, 0, 0, 255, 0, 0, 0, 0}};
  MipChain d = buildMipReference(odd, TexelEncoding::Unorm, MipSource::Level0);
  MipChain c = buildMipReference(odd, TexelEncoding::Unorm, MipSource::PreviousLevel);
  EXPECT_EQ(d.levels[2].texels[0], 0.0);
  EXPECT_GT(c.levels[2].texels[0], 0.0);
  EXPECT_NEAR(c.levels[2].texels[0], 0.5 * (0.6 / 2.2) / 2.5, 1e-15);  // texel 6 is 0.6 of [4.4, 6.6)
}

TEST(MipReference, RejectsBadInput) {
  EXPECT_THROW(buildMipReference(TexelData{2, 2, 5, std::vector<uint8_t>(20)}, TexelEncoding::Unorm), Error);
  EXPECT_THROW(buildMipReference(TexelData{0, 2, 1, {}}, TexelEncoding::Unorm), Error);
  EXPECT_THROW(buildMipReference(TexelData{2, 2, 1, std::vector<uint8_t>(3)}, TexelEncoding::Unorm), Error);
  MipChain chain = buildMipReference(TexelData{1, 1, 1, {7}}, TexelEncoding::Unorm);
  EXPECT_THROW(quantizeMipLevel(chain, 1), Error);
}

}  // namespace
}  // namespace rtr
