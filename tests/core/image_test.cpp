#include "core/image.hpp"

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include <tinyexr.h>

#include <gtest/gtest.h>

#include "core/error.hpp"

namespace rtr {
namespace {

TEST(Image, SrgbTransferRoundTripsEveryByte) {
  for (int i = 0; i < 256; ++i) {
    float lin = srgbToLinear(i / 255.0f);
    EXPECT_EQ(int(std::lround(linearToSrgb(lin) * 255.0f)), i);
  }
}

TEST(Image, PngRoundTripsAndRejectsNonPng) {
  auto dir = std::filesystem::temp_directory_path() / "rtr_image_test";
  std::filesystem::create_directories(dir);
  ImageRGBA8 img{3, 2, {}};
  for (int i = 0; i < 24; ++i) img.pixels.push_back(uint8_t(i * 10));
  savePng(dir / "a.png", img);
  TexelData back = loadImage(dir / "a.png", 4);
  EXPECT_EQ(back.width, 3u);
  EXPECT_EQ(back.height, 2u);
  EXPECT_EQ(back.texels, img.pixels);
  std::ofstream(dir / "b.png") << "not a png";
  EXPECT_THROW(loadImage(dir / "b.png", 4), Error);
  std::filesystem::remove_all(dir);
}

std::string readAll(const std::filesystem::path& f) {
  std::ifstream in(f, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

ImageRGBA8 noise(uint32_t w, uint32_t h) {
  std::mt19937 rng(7);
  ImageRGBA8 img{w, h, std::vector<uint8_t>(size_t(w) * h * 4)};
  for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = uint8_t(i % 7 ? rng() : i / 97);  // noise and ramps
  return img;
}

struct ImageWrite : ::testing::Test {
  std::filesystem::path dir = std::filesystem::temp_directory_path() / ("rtr_image_write_" + std::to_string(::getpid()));
  void SetUp() override { std::filesystem::create_directories(dir); }
  void TearDown() override { std::filesystem::remove_all(dir); }
};

// Big enough that the encoder splits it into strips deflated on several threads.
TEST_F(ImageWrite, PngDecodesToTheSamePixels) {
  for (auto [w, h] : {std::pair{1u, 1u}, {300u, 257u}, {4096u, 97u}}) {
    const ImageRGBA8 img = noise(w, h);
    saveImage(dir / "a.png", img);
    const TexelData back = loadImage(dir / "a.png", 4);
    ASSERT_EQ(back.width, w);
    ASSERT_EQ(back.height, h);
    EXPECT_TRUE(back.texels == img.pixels) << w << "x" << h;
  }
}

TEST_F(ImageWrite, FormatFollowsTheExtension) {
  const ImageRGBA8 img = noise(16, 8);
  saveImage(dir / "a.jpg", img);
  saveImage(dir / "b.JPEG", img);
  saveImage(dir / "a.hdr", img);
  saveImage(dir / "a.exr", img);
  EXPECT_EQ(readAll(dir / "a.jpg").substr(0, 2), "\xFF\xD8");
  EXPECT_EQ(readAll(dir / "b.JPEG").substr(0, 2), "\xFF\xD8");
  EXPECT_EQ(readAll(dir / "a.hdr").substr(0, 10), "#?RADIANCE");
  EXPECT_EQ(readAll(dir / "a.exr").substr(0, 4), "\x76\x2F\x31\x01");
  EXPECT_EQ(loadImage(dir / "a.jpg", 4).width, 16u);
  try {
    saveImage(dir / "a.bmp", img);
    FAIL() << "no error";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find(kImageExtensions), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "a.bmp"));
}

// The tracer's radiance goes to .exr as-is: values above 1 and exact floats survive.
TEST_F(ImageWrite, ExrKeepsLinearFloats) {
  ImageF img{3, 2, {}};
  for (int i = 0; i < 6; ++i) img.pixels.push_back({i * 1.5f, 0.1f * i, 1e-3f, 0.5f});
  saveImage(dir / "r.exr", img);
  float* rgba = nullptr;
  int w = 0, h = 0;
  const char* err = nullptr;
  ASSERT_EQ(LoadEXR(&rgba, &w, &h, (dir / "r.exr").c_str(), &err), TINYEXR_SUCCESS) << (err ? err : "");
  ASSERT_EQ(w, 3);
  ASSERT_EQ(h, 2);
  for (int i = 0; i < 6; ++i)
    for (int c = 0; c < 4; ++c) EXPECT_EQ(rgba[i * 4 + c], img.pixels[i][c]) << i << "," << c;
  std::free(rgba);
}

TEST_F(ImageWrite, ExistingFileKeptWithoutReplace) {
  saveImage(dir / "a.png", noise(2, 2));
  const std::string before = readAll(dir / "a.png");
  EXPECT_THROW(saveImage(dir / "a.png", noise(5, 5), {Replace::No}), OutputExists);
  EXPECT_EQ(readAll(dir / "a.png"), before);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1);
}

}  // namespace
}  // namespace rtr
