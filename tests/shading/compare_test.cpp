#include "core/compare.hpp"

#include <gtest/gtest.h>

#include "core/error.hpp"

namespace rtr {
namespace {

ImageRGBA8 flat(uint32_t w, uint32_t h, std::array<uint8_t, 4> c) {
  ImageRGBA8 img{w, h, {}};
  for (uint32_t i = 0; i < w * h; ++i) img.pixels.insert(img.pixels.end(), c.begin(), c.end());
  return img;
}

// A disc of radius r at (cx, cy): white inside, dark grey outside, like a rendered silhouette.
ImageRGBA8 disc(uint32_t w, uint32_t h, double cx, double cy, double r) {
  ImageRGBA8 img = flat(w, h, {20, 20, 20, 255});
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
      if (dx * dx + dy * dy < r * r) std::fill_n(img.at(x, y), 3, uint8_t(240));
    }
  return img;
}

void set(ImageRGBA8& img, uint32_t x, uint32_t y, std::array<uint8_t, 4> c) { std::copy(c.begin(), c.end(), img.at(x, y)); }

TEST(Compare, IdenticalImagesPass) {
  ImageRGBA8 a = disc(40, 30, 20, 15, 9);
  CompareResult r = compareEdgeTolerant(a, a, 0);
  EXPECT_EQ(r.failingPixels, 0u);
  EXPECT_EQ(r.maxAbsError, 0.0);
  EXPECT_EQ(r.meanAbsError, 0.0);
  EXPECT_EQ(r.errorMap.pixels, flat(40, 30, {0, 0, 0, 255}).pixels);
  EXPECT_FALSE(firstMismatch(a, a).has_value());
}

TEST(Compare, SubPixelShiftedSilhouettePasses) {
  ImageRGBA8 ref = disc(64, 48, 32, 24, 15), test = disc(64, 48, 32.6, 23.7, 15.4);
  CompareResult r = compareEdgeTolerant(test, ref, 2);
  EXPECT_EQ(r.failingPixels, 0u);
  EXPECT_EQ(r.maxAbsError, 220.0);         // silhouette pixels differ completely at the same place...
  EXPECT_EQ(r.maxAbsErrorPassing, 220.0);  // ...and still pass through a neighbour
  EXPECT_GT(r.meanAbsError, 0.0);
  ASSERT_TRUE(firstMismatch(test, ref).has_value());
}

TEST(Compare, ShiftBeyondOnePixelFails) {
  ImageRGBA8 ref = disc(64, 48, 32, 24, 15), test = disc(64, 48, 34.5, 24, 15);
  CompareResult r = compareEdgeTolerant(test, ref, 2);
  EXPECT_GT(r.failingPixels, 0u);
  EXPECT_LT(r.failingFraction, 0.1);
}

TEST(Compare, RealChangeFailsAndIsMarkedRed) {
  ImageRGBA8 ref = disc(32, 32, 16, 16, 8), test = ref;
  set(test, 16, 16, {200, 240, 240, 255});  // inside the flat disc: no neighbour explains it
  set(test, 3, 4, {20, 20, 25, 255});       // 5 off in blue: within the threshold
  CompareResult r = compareEdgeTolerant(test, ref, 8);
  EXPECT_EQ(r.failingPixels, 1u);
  EXPECT_DOUBLE_EQ(r.failingFraction, 1.0 / (32 * 32));
  EXPECT_EQ(r.maxAbsError, 40.0);
  EXPECT_EQ(r.maxAbsErrorPassing, 5.0);
  EXPECT_DOUBLE_EQ(r.meanAbsError, (40.0 + 5.0) / (4.0 * 32 * 32));
  EXPECT_DOUBLE_EQ(r.meanAbsErrorPassing, 5.0 / (4.0 * (32 * 32 - 1)));
  const uint8_t* red = r.errorMap.at(16, 16);
  EXPECT_EQ((std::array<uint8_t, 4>{red[0], red[1], red[2], red[3]}), (std::array<uint8_t, 4>{255, 0, 0, 255}));
  EXPECT_EQ(r.errorMap.at(3, 4)[0], 159);  // 5 * 255 / 8, grey
  EXPECT_EQ(r.errorMap.at(3, 4)[1], 159);
  EXPECT_EQ(r.errorMap.at(0, 0)[0], 0);
}

TEST(Compare, ThresholdIsInclusive) {
  ImageRGBA8 ref = flat(3, 3, {100, 100, 100, 255}), test = ref;
  set(test, 1, 1, {108, 100, 92, 255});
  EXPECT_EQ(compareEdgeTolerant(test, ref, 8).failingPixels, 0u);
  EXPECT_EQ(compareEdgeTolerant(test, ref, 7).failingPixels, 1u);
}

TEST(Compare, OneNeighbourMustMatchAllChannels) {
  // Red on the left, green on the right: yellow matches each channel somewhere, but no single pixel.
  ImageRGBA8 ref = flat(2, 1, {255, 0, 0, 255});
  set(ref, 1, 0, {0, 255, 0, 255});
  ImageRGBA8 test = ref;
  set(test, 0, 0, {255, 255, 0, 255});
  CompareResult r = compareEdgeTolerant(test, ref, 4);
  EXPECT_EQ(r.failingPixels, 1u);
  EXPECT_EQ(r.errorMap.at(0, 0)[0], 255);
  EXPECT_EQ(r.errorMap.at(0, 0)[1], 0);
}

TEST(Compare, FirstMismatchIsRowMajor) {
  ImageRGBA8 ref = flat(5, 4, {1, 2, 3, 4}), test = ref;
  set(test, 4, 1, {1, 2, 3, 5});
  set(test, 0, 2, {9, 9, 9, 9});
  auto d = firstMismatch(test, ref);
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->x, 4u);
  EXPECT_EQ(d->y, 1u);
  EXPECT_EQ(d->test, (std::array<uint8_t, 4>{1, 2, 3, 5}));
  EXPECT_EQ(d->ref, (std::array<uint8_t, 4>{1, 2, 3, 4}));
}

TEST(Compare, SizeMismatchThrows) {
  EXPECT_THROW(compareEdgeTolerant(flat(2, 2, {}), flat(2, 3, {}), 1), Error);
  EXPECT_THROW(firstMismatch(flat(2, 2, {}), flat(3, 2, {})), Error);
  ImageRGBA8 broken{2, 2, std::vector<uint8_t>(3)};
  EXPECT_THROW(compareEdgeTolerant(broken, broken, 1), Error);
}

}  // namespace
}  // namespace rtr
