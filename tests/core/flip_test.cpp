#include "core/flip.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <glm/common.hpp>
#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include "core/error.hpp"

namespace rtr {
namespace {

ImageF uniform(uint32_t w, uint32_t h, glm::vec3 c) {
  return ImageF{w, h, std::vector<glm::vec4>(size_t(w) * h, glm::vec4(c, 1.0f))};
}

ImageF noise(uint32_t w, uint32_t h, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  ImageF img = uniform(w, h, glm::vec3(0));
  for (glm::vec4& p : img.pixels) p = {u(rng), u(rng), u(rng), 1.0f};
  return img;
}

ImageRGBA8 grey8(uint32_t w, uint32_t h, uint8_t v) { return ImageRGBA8{w, h, std::vector<uint8_t>(size_t(w) * h * 4, v)}; }

// A vertical edge between sRGB levels lo (left) and hi, starting at column x0.
ImageRGBA8 edge8(uint32_t w, uint32_t h, uint32_t x0, uint8_t lo, uint8_t hi) {
  ImageRGBA8 img = grey8(w, h, lo);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = x0; x < w; ++x) std::fill_n(img.at(x, y), 3, hi);
  return img;
}

double meanAbsDifference(const ImageRGBA8& a, const ImageRGBA8& b) {
  double s = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i)
    if (i % 4 != 3) s += std::abs(int(a.pixels[i]) - int(b.pixels[i]));
  return s / double(a.pixels.size() / 4 * 3);
}

TEST(Flip, IdenticalImagesGiveZeroEverywhere) {
  const ImageF a = noise(37, 23, 1);
  const FlipResult r = flip(a, a);
  ASSERT_EQ(r.error.size(), 37u * 23u);
  for (float e : r.error) ASSERT_EQ(e, 0.0f);
  EXPECT_EQ(r.stats().mean, 0.0);
  const ImageRGBA8 e = edge8(16, 16, 8, 10, 240);
  EXPECT_EQ(flip(e, e).stats().max, 0.0);
}

// Along three directions of colour (lightness, red, blue), a larger step is a larger error.
TEST(Flip, ErrorGrowsWithTheColourDifference) {
  const glm::vec3 base(0.2f, 0.2f, 0.2f);
  for (const glm::vec3 dir : {glm::vec3(1, 1, 1), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1)}) {
    double last = 0;
    for (int k = 1; k <= 16; ++k) {
      const double m = flip(uniform(8, 8, base), uniform(8, 8, base + 0.05f * float(k) * dir)).stats().mean;
      EXPECT_GT(m, last) << "step " << k << " along (" << dir.x << ", " << dir.y << ", " << dir.z << ")";
      last = m;
    }
  }
}

ImageF linear(const ImageRGBA8& img) {
  ImageF f{img.width, img.height, {}};
  for (size_t i = 0; i < img.pixels.size(); i += 4)
    f.pixels.emplace_back(srgbToLinear(img.pixels[i] / 255.0f), srgbToLinear(img.pixels[i + 1] / 255.0f),
                          srgbToLinear(img.pixels[i + 2] / 255.0f), 1.0f);
  return f;
}

double mean(const std::vector<float>& v) {
  double s = 0;
  for (float e : v) s += e;
  return s / double(v.size());
}

// The eye's contrast sensitivity: a one-pixel checkerboard of ±8 steps blends into its mean at 67 pixels a
// degree, a uniform change of 8 steps does not, though both differ from the reference by 8 steps a pixel.
TEST(Flip, FineDetailIsSeenLessThanAUniformChangeOfTheSameMeanDifference) {
  const ImageRGBA8 ref = grey8(32, 32, 128), brighter = grey8(32, 32, 136);
  ImageRGBA8 checker = ref;
  for (uint32_t y = 0; y < 32; ++y)
    for (uint32_t x = 0; x < 32; ++x) std::fill_n(checker.at(x, y), 3, uint8_t((x + y) % 2 ? 136 : 120));
  ASSERT_EQ(meanAbsDifference(ref, checker), meanAbsDifference(ref, brighter));
  const double fine = flip(ref, checker).stats().mean, flat = flip(ref, brighter).stats().mean;
  EXPECT_LT(fine, 0.5 * flat) << "checkerboard " << fine << ", uniform change " << flat;
}

// The feature pipeline: the colour pipeline's blur softens an edge moved by one pixel, the edge detectors
// see it move; a uniform brightness change moves no edge and is left (nearly) as the colour error says.
TEST(Flip, FeaturesRaiseTheErrorOfAMovedEdgeNotOfAUniformChange) {
  const ImageRGBA8 ref = edge8(64, 32, 32, 64, 192), shifted = edge8(64, 32, 33, 64, 192);
  ImageRGBA8 brighter = ref;
  for (size_t i = 0; i < brighter.pixels.size(); ++i)
    if (i % 4 != 3) brighter.pixels[i] += 2;
  const ImageF r = linear(ref), s = linear(shifted), b = linear(brighter);
  const double moved = flip(r, s).stats().mean, movedColour = mean(flipColourError(r, s));
  const double flat = flip(r, b).stats().mean, flatColour = mean(flipColourError(r, b));
  EXPECT_GT(moved, 1.25 * movedColour) << moved << " against the colour pipeline's " << movedColour;
  EXPECT_LT(flat, 1.1 * flatColour) << flat << " against the colour pipeline's " << flatColour;
  const std::vector<float> feature = flipFeatureError(r, s);
  EXPECT_GT(*std::max_element(feature.begin(), feature.end()), 0.2f);
  for (float f : flipFeatureError(r, r)) ASSERT_EQ(f, 0.0f);
}

// Every step compares the two images through |x − y| or a length of differences, so swapping them gives
// the same map bit for bit. The filters are symmetric (derivatives antisymmetric, used as magnitudes) and
// the border repeats, so mirroring both images mirrors the map (up to rounding).
TEST(Flip, SymmetricInItsImagesAndUnderMirroring) {
  const ImageF a = noise(31, 17, 2), b = noise(31, 17, 3);
  const FlipResult ab = flip(a, b), ba = flip(b, a);
  EXPECT_EQ(ab.error, ba.error);
  auto mirror = [](const ImageF& img) {
    ImageF m = img;
    for (uint32_t y = 0; y < img.height; ++y)
      for (uint32_t x = 0; x < img.width; ++x) m.at(img.width - 1 - x, y) = img.at(x, y);
    return m;
  };
  const FlipResult mm = flip(mirror(a), mirror(b));
  for (uint32_t y = 0; y < a.height; ++y)
    for (uint32_t x = 0; x < a.width; ++x)
      ASSERT_NEAR(mm.error[y * a.width + a.width - 1 - x], ab.error[y * a.width + x], 1e-5) << x << ", " << y;
}

// The largest error is defined as the one between pure green and pure blue: no pair of the RGB cube's
// corners exceeds it, and noise of any colour stays within [0, 1].
TEST(Flip, ValuesStayInZeroToOneAndGreenAgainstBlueIsTheLargest) {
  double largest = 0;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) {
      const glm::vec3 ci(i & 1, (i >> 1) & 1, (i >> 2) & 1), cj(j & 1, (j >> 1) & 1, (j >> 2) & 1);
      const double e = flip(uniform(4, 4, ci), uniform(4, 4, cj)).stats().max;
      EXPECT_LE(e, 1.0 + 1e-6) << i << " against " << j;
      largest = std::max(largest, e);
    }
  EXPECT_NEAR(flip(uniform(4, 4, {0, 1, 0}), uniform(4, 4, {0, 0, 1})).stats().mean, 1.0, 1e-4);
  EXPECT_NEAR(largest, 1.0, 1e-4);
  ImageF wild = noise(40, 40, 4), other = noise(40, 40, 5);
  for (glm::vec4& p : wild.pixels) p = glm::round(p);  // saturated corners: the largest edges
  // Any viewing distance: detectors narrower than a pixel (1 ppd) or wider than the image (1000 ppd);
  // flat images have no features to differ in at any of them (float rounding of the detectors' zero sum,
  // about 1e-8, shows as 1e-4 through the feature error's square root).
  for (double ppd : {1.0, 67.0, 1000.0}) {
    for (float e : flip(wild, other, {.ppd = ppd}).error) {
      ASSERT_GE(e, 0.0f) << ppd;
      ASSERT_LE(e, 1.0f) << ppd;
    }
    for (float f : flipFeatureError(uniform(6, 6, {0.1f, 0.2f, 0.3f}), uniform(6, 6, {0.9f, 0.5f, 0.1f}), {.ppd = ppd}))
      ASSERT_LT(f, 1e-3f) << ppd;
  }
}

// Seen from farther away (more pixels a degree), a one-pixel checkerboard blends into its mean grey.
TEST(Flip, FineDetailMattersLessFromFartherAway) {
  ImageF checker = uniform(32, 32, glm::vec3(0));
  for (uint32_t y = 0; y < 32; ++y)
    for (uint32_t x = 0; x < 32; ++x) checker.at(x, y) = glm::vec4(glm::vec3(float((x + y) & 1)), 1.0f);
  const ImageF grey = uniform(32, 32, glm::vec3(0.5f));
  const double near = flip(checker, grey, {.ppd = 10}).stats().mean, far = flip(checker, grey, {.ppd = 200}).stats().mean;
  EXPECT_GT(near, 2.0 * far) << near << " at 10 ppd, " << far << " at 200";
}

TEST(Flip, StatsOverAMask) {
  FlipResult r{10, 10, std::vector<float>(100)};
  for (int i = 0; i < 100; ++i) r.error[i] = float(i) / 100.0f;
  const FlipStats all = r.stats();
  EXPECT_EQ(all.pixels, 100u);
  EXPECT_NEAR(all.mean, 0.495, 1e-6);      // (0 + 1 + ... + 99) / 100 / 100
  EXPECT_FLOAT_EQ(float(all.p99), 0.98f);  // 99 of the 100 are at or below the 99th smallest
  EXPECT_FLOAT_EQ(float(all.max), 0.99f);
  std::vector<bool> even(100);
  for (int i = 0; i < 100; i += 2) even[i] = true;
  const FlipStats half = r.stats(&even);
  EXPECT_EQ(half.pixels, 50u);
  EXPECT_NEAR(half.mean, 0.49, 1e-6);  // 2 (0 + ... + 49) / 50 / 100
}

TEST(Flip, HeatMapBrightensWithTheError) {
  FlipResult r{11, 1, std::vector<float>(11)};
  for (int i = 0; i <= 10; ++i) r.error[i] = float(i) / 10.0f;
  const ImageRGBA8 m = flipHeatMap(r);
  int last = -1;
  for (uint32_t x = 0; x <= 10; ++x) {
    const uint8_t* p = m.at(x, 0);
    const int luma = 2 * p[0] + 5 * p[1] + p[2];
    EXPECT_GT(luma, last) << x;
    last = luma;
  }
  EXPECT_EQ(m.at(0, 0)[0] + m.at(0, 0)[1] + m.at(0, 0)[2], 0);
}

TEST(Flip, RejectsNonFiniteValuesEmptyImagesAndSizeMismatches) {
  const ImageF a = noise(5, 4, 6);
  for (float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    ImageF b = a;
    b.at(2, 1).g = bad;
    try {
      flip(a, b);
      FAIL() << "accepted " << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("second image"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("(2, 1)"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(flip(ImageF{}, ImageF{}), Error);
  EXPECT_THROW(flip(a, noise(4, 5, 7)), Error);
  ImageF shortBuffer = a;
  shortBuffer.pixels.pop_back();
  EXPECT_THROW(flip(a, shortBuffer), Error);
  EXPECT_THROW(flip(grey8(3, 3, 0), grey8(3, 2, 0)), Error);
  EXPECT_THROW(flip(a, a, {.ppd = 0}), Error);
}

}  // namespace
}  // namespace rtr
