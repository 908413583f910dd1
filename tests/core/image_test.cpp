#include "core/image.hpp"

#include <cmath>
#include <fstream>

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

}  // namespace
}  // namespace rtr
