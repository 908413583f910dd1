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
  } catch (const UsageError& e) { EXPECT_NE(std::string(e.what()).find(kImageExtensions), std::string::npos) << e.what(); }
  EXPECT_FALSE(std::filesystem::exists(dir / "a.bmp"));
}

// JPEG decodes through libjpeg-turbo: a smooth image comes back close (lossy) in every channel count the
// texture slots ask for, alpha opaque; truncated or broken files are errors naming the file, never a crash.
// A PNG asked for fewer or more channels: grey is stb's integer luma, alpha kept or opaque, as the
// textures always had (the renderers' roughness and mask textures are read as one channel).
TEST_F(ImageWrite, PngConvertsChannelsAsBefore) {
  const ImageRGBA8 img = noise(37, 11);
  saveImage(dir / "c.png", img);
  for (int channels : {1, 2, 3}) {
    const TexelData t = loadImage(dir / "c.png", channels);
    ASSERT_EQ(t.texels.size(), size_t(37 * 11 * channels));
    for (size_t i = 0; i < size_t(37 * 11); ++i) {
      const uint8_t* s = &img.pixels[i * 4];
      const uint8_t* d = &t.texels[i * channels];
      if (channels == 3) {
        ASSERT_TRUE(d[0] == s[0] && d[1] == s[1] && d[2] == s[2]) << "pixel " << i;
      } else {
        ASSERT_EQ(d[0], (s[0] * 77 + s[1] * 150 + s[2] * 29) >> 8) << "pixel " << i;
        if (channels == 2) { ASSERT_EQ(d[1], s[3]) << "pixel " << i; }
      }
    }
  }
}

// One bit flipped inside the compressed image data: stb_image 2.27 checks neither the chunk's CRC nor
// zlib's checksum and decoded such a file into wrong texels without a word; now it is refused by name.
TEST_F(ImageWrite, DamagedPngIsRefusedNotDecodedWrong) {
  saveImage(dir / "ok.png", noise(64, 64));
  std::string bytes = readAll(dir / "ok.png");
  const size_t idat = bytes.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  ASSERT_GT(bytes.size(), idat + 300);
  bytes[idat + 200] = char(bytes[idat + 200] ^ 0x10);
  std::ofstream(dir / "flipped.png", std::ios::binary) << bytes;
  try {
    loadImage(dir / "flipped.png", 4);
    ADD_FAILURE() << "a damaged PNG was decoded";
  } catch (const Error& e) { EXPECT_NE(std::string(e.what()).find("flipped.png"), std::string::npos) << e.what(); }
}

// Formats no scene names as a texture are not decoded at all (stb's PNM reader overflows on long numbers):
// refused, naming the file, like any file that is no image.
TEST_F(ImageWrite, UnsupportedFormatsAreRefusedByName) {
  std::ofstream(dir / "t.ppm", std::ios::binary) << "P6 2 2 255\n" << std::string(12, '\x7f');
  std::ofstream(dir / "t.gif", std::ios::binary) << "GIF89a" << std::string(20, '\0');
  for (const char* f : {"t.ppm", "t.gif"}) {
    try {
      loadImage(dir / f, 4);
      ADD_FAILURE() << f << " was decoded";
    } catch (const Error& e) { EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what(); }
  }
}

// A JPEG whose data ends early is refused by name, not padded with grey: libjpeg only warns. Before, a
// header claiming 30000² pixels over the same few hundred bytes of data decoded into 900 MB of filler.
TEST_F(ImageWrite, JpegWhoseDataEndsEarlyIsRefused) {
  saveImage(dir / "ok.jpg", noise(64, 48));
  const std::string bytes = readAll(dir / "ok.jpg");
  ASSERT_NO_THROW(loadImage(dir / "ok.jpg", 1));
  std::ofstream(dir / "cut.jpg", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  std::string big = bytes;
  const size_t sof = big.find("\xFF\xC0");
  ASSERT_NE(sof, std::string::npos);
  for (size_t at : {sof + 5, sof + 7}) big[at] = char(30000 >> 8), big[at + 1] = char(30000 & 255);  // height, width
  std::ofstream(dir / "huge.jpg", std::ios::binary) << big;
  for (const char* f : {"cut.jpg", "huge.jpg"}) {
    try {
      const TexelData t = loadImage(dir / f, 1);
      ADD_FAILURE() << f << " was decoded as " << t.width << "x" << t.height;
    } catch (const Error& e) { EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what(); }
  }
}

TEST_F(ImageWrite, JpegDecodesInEveryChannelCount) {
  ImageRGBA8 img{64, 48, std::vector<uint8_t>(64 * 48 * 4)};
  for (uint32_t y = 0; y < 48; ++y)
    for (uint32_t x = 0; x < 64; ++x) {
      uint8_t* p = &img.pixels[(y * 64 + x) * 4];
      p[0] = uint8_t(x * 4), p[1] = uint8_t(y * 5), p[2] = 128, p[3] = 7;
    }
  saveImage(dir / "g.jpg", img);
  for (int channels : {1, 2, 3, 4}) {
    const TexelData t = loadImage(dir / "g.jpg", channels);
    ASSERT_EQ(t.width, 64u);
    ASSERT_EQ(t.height, 48u);
    ASSERT_EQ(t.texels.size(), size_t(64 * 48 * channels));
    const uint8_t* p = &t.texels[(20 * 64 + 30) * channels];
    if (channels >= 3) {
      EXPECT_NEAR(p[0], 120, 6) << channels;
      EXPECT_NEAR(p[1], 100, 6) << channels;
      EXPECT_NEAR(p[2], 128, 6) << channels;
    } else {
      EXPECT_NEAR(p[0], 0.299 * 120 + 0.587 * 100 + 0.114 * 128, 6) << channels;  // luma
    }
    if (channels % 2 == 0) { EXPECT_EQ(p[channels - 1], 255) << "alpha is opaque"; }
  }
  const std::string bytes = readAll(dir / "g.jpg");
  std::ofstream(dir / "cut.jpg", std::ios::binary) << bytes.substr(0, 200);
  std::string bad = bytes;
  for (size_t i = 20; i < 400 && i < bad.size(); ++i) bad[i] = char(0xFF);  // tables overwritten
  std::ofstream(dir / "bad.jpg", std::ios::binary) << bad;
  for (const char* f : {"cut.jpg", "bad.jpg"}) {
    try {
      const TexelData t = loadImage(dir / f, 4);
      EXPECT_EQ(t.texels.size(), size_t(t.width) * t.height * 4) << f;  // recovered: still consistent
    } catch (const Error& e) { EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what(); }
  }
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
