// Our BC1/BC3/BC4 encoder and decoders (scene/bc.hpp): blocks decode as Vulkan's data format specification
// defines them; flat blocks come back within 1 per channel and two-colour blocks exactly; the least-squares
// refinement beats the plain endpoints it starts from; a level encodes to the same bytes on any thread count.
#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "scene/baked_texels.hpp"
#include "scene/bc.hpp"

using namespace rtr;

namespace {

std::array<uint8_t, 8> block(uint16_t c0, uint16_t c1, uint32_t indices) {
  return {uint8_t(c0),           uint8_t(c0 >> 8),       uint8_t(c1),           uint8_t(c1 >> 8), uint8_t(indices),
          uint8_t(indices >> 8), uint8_t(indices >> 16), uint8_t(indices >> 24)};
}

int expand(int x, int bits) { return (x << (8 - bits)) | (x >> (2 * bits - 8)); }

// Squared RGB error of a BC1 block against its texels.
int colourError(const uint8_t rgba[64], const uint8_t b[8]) {
  uint8_t back[64];
  bc::decodeColour(b, true, back);
  int e = 0;
  for (int i = 0; i < 16; ++i)
    for (int k = 0; k < 3; ++k) e += (back[4 * i + k] - rgba[4 * i + k]) * (back[4 * i + k] - rgba[4 * i + k]);
  return e;
}

int channelError(const uint8_t t[16], const uint8_t b[8]) {
  uint8_t back[16];
  bc::decodeChannel(b, back, 1);
  int e = 0;
  for (int i = 0; i < 16; ++i) e += (back[i] - t[i]) * (back[i] - t[i]);
  return e;
}

// Smooth content with a little noise, as texture blocks mostly are.
void smoothBlock(std::mt19937& rng, uint8_t rgba[64]) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  float base[3], dx[3], dy[3];
  for (int k = 0; k < 3; ++k) base[k] = 255 * u(rng), dx[k] = 30 * (u(rng) - 0.5f), dy[k] = 30 * (u(rng) - 0.5f);
  for (int i = 0; i < 16; ++i) {
    for (int k = 0; k < 3; ++k)
      rgba[4 * i + k] =
          uint8_t(std::clamp(base[k] + dx[k] * float(i % 4) + dy[k] * float(i / 4) + 6 * (u(rng) - 0.5f), 0.0f, 255.0f));
    rgba[4 * i + 3] = 255;
  }
}

}  // namespace

TEST(Bc, DecodersReadBlocksAsTheSpecificationDefinesThem) {
  uint8_t t[64];
  // Four colours (c0 > c1): red, blue, then 2:1 and 1:2 mixes (170 and 85 exactly).
  const auto four = block(0xF800, 0x001F, 0b11100100);
  bc::decodeColour(four.data(), true, t);
  const int want4[4][3] = {{255, 0, 0}, {0, 0, 255}, {170, 0, 85}, {85, 0, 170}};
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(t[4 * i + k], want4[i][k]) << "texel " << i << " channel " << k;
  // c0 <= c1: BC1 has three colours (the midpoint) and black; BC3's colour half four colours all the same.
  // Green 1 and 4 of 63 widen to 4 and 16: midpoint 10, mixes 8 and 12.
  const auto three = block(0x0020, 0x0080, 0b11100100);
  bc::decodeColour(three.data(), true, t);
  EXPECT_EQ(t[1], 4);
  EXPECT_EQ(t[5], 16);
  EXPECT_EQ(t[9], 10);
  EXPECT_EQ(t[12], 0);
  EXPECT_EQ(t[13], 0);
  EXPECT_EQ(t[14], 0);
  bc::decodeColour(three.data(), false, t);
  EXPECT_EQ(t[9], 8);
  EXPECT_EQ(t[13], 12);
  // BC4, eight values (200 > 60: sevenths) and six (50 <= 100: fifths, then 0 and 255); index i for texel i.
  uint8_t v[16];
  uint64_t bits = 0;
  for (int i = 0; i < 16; ++i) bits |= uint64_t(i < 8 ? i : 15 - i) << (3 * i);
  uint8_t b4[8] = {200, 60};
  for (int b = 0; b < 6; ++b) b4[2 + b] = uint8_t(bits >> (8 * b));
  bc::decodeChannel(b4, v, 1);
  const int want8[8] = {200, 60, 180, 160, 140, 120, 100, 80};
  for (int i = 0; i < 8; ++i) EXPECT_EQ(v[i], want8[i]) << i;
  b4[0] = 50, b4[1] = 100;
  bc::decodeChannel(b4, v, 1);
  const int want6[8] = {50, 100, 60, 70, 80, 90, 0, 255};
  for (int i = 0; i < 8; ++i) EXPECT_EQ(v[i], want6[i]) << i;
  EXPECT_EQ(v[15], 50);
}

TEST(Bc, FlatBlocksWithinOneStepTwoColourBlocksExact) {
  std::mt19937 rng(3);
  uint8_t rgba[64], b[8], back[64];
  for (int n = 0; n < 1256; ++n) {
    const uint8_t c[3] = {uint8_t(n < 256 ? n : rng()), uint8_t(n < 256 ? n : rng()), uint8_t(n < 256 ? n : rng())};
    for (int i = 0; i < 16; ++i) rgba[4 * i] = c[0], rgba[4 * i + 1] = c[1], rgba[4 * i + 2] = c[2], rgba[4 * i + 3] = 255;
    bc::encodeColour(rgba, b);
    bc::decodeColour(b, true, back);
    for (int i = 0; i < 16; ++i)
      for (int k = 0; k < 3; ++k) ASSERT_LE(std::abs(back[4 * i + k] - c[k]), 1) << "colour " << n << " channel " << k;
    uint8_t flat[16], one[16];
    std::fill(flat, flat + 16, c[0]);
    bc::encodeChannel(flat, b);
    bc::decodeChannel(b, one, 1);
    ASSERT_EQ(std::vector<uint8_t>(one, one + 16), std::vector<uint8_t>(flat, flat + 16));
  }
  // Two colours that RGB565 holds exactly, in any arrangement: both endpoints found.
  for (int n = 0; n < 1000; ++n) {
    int c[2][3];
    for (auto& x : c) x[0] = expand(int(rng() % 32), 5), x[1] = expand(int(rng() % 64), 6), x[2] = expand(int(rng() % 32), 5);
    const uint32_t which = rng();
    for (int i = 0; i < 16; ++i)
      for (int k = 0; k < 3; ++k) rgba[4 * i + k] = uint8_t(c[(which >> i) & 1][k]);
    bc::encodeColour(rgba, b);
    ASSERT_EQ(colourError(rgba, b), 0) << "pair " << n;
    uint8_t two[16];
    for (int i = 0; i < 16; ++i) two[i] = uint8_t(c[(which >> i) & 1][1]);
    bc::encodeChannel(two, b);
    ASSERT_EQ(channelError(two, b), 0) << "pair " << n;
  }
}

TEST(Bc, RefinementBeatsThePlainEndpoints) {
  // The plain choices: BC1 endpoints at the corners of the texels' box, BC4 at their extremes, each texel
  // the nearest colour (what a range fit does).
  std::mt19937 rng(11);
  long long ours = 0, plain = 0, ours4 = 0, plain4 = 0;
  for (int n = 0; n < 4000; ++n) {
    uint8_t rgba[64], b[8];
    smoothBlock(rng, rgba);
    bc::encodeColour(rgba, b);
    ours += colourError(rgba, b);
    int lo[3] = {255, 255, 255}, hi[3] = {0, 0, 0};
    for (int i = 0; i < 16; ++i)
      for (int k = 0; k < 3; ++k) lo[k] = std::min<int>(lo[k], rgba[4 * i + k]), hi[k] = std::max<int>(hi[k], rgba[4 * i + k]);
    auto q565 = [](const int c[3]) {
      return uint16_t((c[0] * 31 + 127) / 255 << 11 | (c[1] * 63 + 127) / 255 << 5 | (c[2] * 31 + 127) / 255);
    };
    const uint16_t c0 = std::max(q565(hi), q565(lo)), c1 = std::min(q565(hi), q565(lo));
    int best = 1 << 30;  // each texel its nearest of the four colours
    uint8_t pal[64];
    const auto ramp = block(c0, c1, 0b11100100);
    bc::decodeColour(ramp.data(), false, pal);
    int e = 0;
    for (int i = 0; i < 16; ++i) {
      best = 1 << 30;
      for (int j = 0; j < 4; ++j) {
        int d = 0;
        for (int k = 0; k < 3; ++k) d += (pal[4 * j + k] - rgba[4 * i + k]) * (pal[4 * j + k] - rgba[4 * i + k]);
        best = std::min(best, d);
      }
      e += best;
    }
    plain += e;

    uint8_t t[16];
    for (int i = 0; i < 16; ++i) t[i] = rgba[4 * i + 1];
    bc::encodeChannel(t, b);
    const int got = channelError(t, b);
    const uint8_t lo4 = *std::min_element(t, t + 16), hi4 = *std::max_element(t, t + 16);
    uint8_t ext[8] = {hi4, lo4}, vals[16];
    uint64_t bits = 0;
    for (int i = 0; i < 8; ++i) bits |= uint64_t(i) << (3 * i);
    for (int k = 0; k < 6; ++k) ext[2 + k] = uint8_t(bits >> (8 * k));
    bc::decodeChannel(ext, vals, 1);  // the eight values between the extremes
    int e4 = 0;
    for (int i = 0; i < 16; ++i) {
      int d = 1 << 30;
      for (int j = 0; j < (hi4 > lo4 ? 8 : 1); ++j) d = std::min(d, (vals[j] - t[i]) * (vals[j] - t[i]));
      e4 += d;
    }
    ASSERT_LE(got, e4) << "block " << n << ": BC4 worse than its extremes";
    ours4 += got, plain4 += e4;
  }
  std::printf("squared error, ours vs plain: BC1 %lld vs %lld, BC4 %lld vs %lld\n", ours, plain, ours4, plain4);
  // BC1: the principal axis alone gives 0.43 of the box corners' error on these blocks, its refinement 0.39.
  EXPECT_LT(double(ours), 0.41 * double(plain));
  EXPECT_LT(double(ours4), 0.9 * double(plain4));
}

TEST(Bc, ALevelEncodesToTheSameBytesOnAnyThreadCountAndDecodesToItsSize) {
  // 300 x 201: 51 rows of blocks (several pieces), the last column and row of blocks partly outside.
  const uint32_t w = 300, h = 201;
  std::mt19937 rng(5);
  std::vector<uint8_t> opaque(size_t(w) * h * 4), alpha, grey(size_t(w) * h);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      uint8_t* p = &opaque[(size_t(y) * w + x) * 4];
      p[0] = uint8_t(x * 255 / w), p[1] = uint8_t(y * 255 / h), p[2] = uint8_t((x + y) % 256), p[3] = 255;
      grey[size_t(y) * w + x] = uint8_t((x * y / 37 + rng() % 8) % 256);
    }
  alpha = opaque;
  for (size_t i = 0; i < alpha.size() / 4; ++i) alpha[4 * i + 3] = uint8_t(i % w < 150 ? 255 : i / w);
  for (BakedFormat f : {BakedFormat::Bc1, BakedFormat::Bc3, BakedFormat::Bc4}) {
    const std::vector<uint8_t>& in = f == BakedFormat::Bc4 ? grey : f == BakedFormat::Bc3 ? alpha : opaque;
    const std::vector<uint8_t> one = encodeBakedLevel(f, w, h, in.data(), 1);
    ASSERT_EQ(one.size(), bakedLevelBytes(f, w, h));
    for (unsigned threads : {2u, 3u, 8u, 0u})
      EXPECT_EQ(encodeBakedLevel(f, w, h, in.data(), threads), one) << threads << " threads";
    // Every texel decoded, the partial blocks' included, near its input: the smooth channels (red, green,
    // alpha) within 40 everywhere, the rest (blue wraps from 255 to 0, the grey is noisy) on average.
    const std::vector<uint8_t> back = decodeBakedLevel(f, w, h, one.data());
    ASSERT_EQ(back.size(), in.size());
    const uint32_t ch = bakedChannels(f);
    double sum = 0;
    int smoothMax = 0;
    for (size_t i = 0; i < back.size(); ++i) {
      const int d = std::abs(int(back[i]) - int(in[i]));
      sum += d;
      if (ch == 4 && i % 4 != 2) smoothMax = std::max(smoothMax, d);
    }
    EXPECT_LE(smoothMax, 40) << "format " << int(f);
    EXPECT_LT(sum / double(back.size()), 6.0) << "format " << int(f);
  }
  // A block's texels outside a level are not read back: a 1 x 1 BC4 level takes texel 0's value (red_1
  // here), whatever the other 15 indices say (a file from another encoder may set them to anything).
  const uint8_t one[8] = {200, 60, 1, 0, 0, 0, 0, 0};
  EXPECT_EQ(decodeBakedLevel(BakedFormat::Bc4, 1, 1, one), std::vector<uint8_t>{60});
}
