#pragma once
// CPU images: 8-bit RGBA for files, float RGBA for linear-light work. PNG I/O through stb.
#include <cstdint>
#include <filesystem>
#include <vector>

#include <glm/vec4.hpp>

namespace rtr {

struct ImageRGBA8 {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> pixels;  // row-major, 4 bytes a pixel, top row first
  uint8_t* at(uint32_t x, uint32_t y) { return &pixels[(size_t(y) * width + x) * 4]; }
  const uint8_t* at(uint32_t x, uint32_t y) const { return &pixels[(size_t(y) * width + x) * 4]; }
};

struct ImageF {
  uint32_t width = 0, height = 0;
  std::vector<glm::vec4> pixels;  // linear light unless said otherwise
  glm::vec4& at(uint32_t x, uint32_t y) { return pixels[size_t(y) * width + x]; }
  const glm::vec4& at(uint32_t x, uint32_t y) const { return pixels[size_t(y) * width + x]; }
};

// Decoded 8-bit texture data with the channel count forced to `channels` (1..4).
struct TexelData {
  uint32_t width = 0, height = 0, channels = 0;
  std::vector<uint8_t> texels;
};

TexelData loadImage(const std::filesystem::path& file, int channels);  // throws rtr::Error naming the file
void savePng(const std::filesystem::path& file, const ImageRGBA8& image);  // atomic: temp file + rename

float srgbToLinear(float c);
float linearToSrgb(float c);
ImageRGBA8 toSrgb8(const ImageF& linear);  // clamps to [0,1], encodes sRGB, alpha linear

}  // namespace rtr
