#pragma once
// CPU images: 8-bit RGBA for files, float RGBA for linear-light work. Reading through stb; writing PNG,
// JPEG, Radiance HDR and OpenEXR, always atomically (core/atomic_file.hpp).
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <glm/vec4.hpp>

#include "core/atomic_file.hpp"

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

// Both throw rtr::Error naming the file (`name`): a bad or oversized header, a decode error, out of memory.
TexelData loadImage(const std::filesystem::path& file, int channels);
TexelData decodeImage(std::span<const uint8_t> bytes, const std::string& name, int channels);
void savePng(const std::filesystem::path& file, const ImageRGBA8& image);  // PNG whatever the name says
void writePng(AtomicFile& file, const ImageRGBA8& image);                  // into an open file; the caller commits it
// A linear-light image, .hdr (Radiance) or .exr (OpenEXR), as floats. Throws rtr::Error naming the file.
ImageF loadLinearImage(const std::filesystem::path& file);

// Output format by extension; anything else is a UsageError that lists these.
enum class ImageFormat { Png, Jpg, Exr, Hdr };
inline constexpr const char* kImageExtensions = ".png, .jpg (or .jpeg), .exr, .hdr";
ImageFormat imageFormatFor(const std::filesystem::path& file);

struct ImageWriteOptions {
  Replace replace = Replace::Yes;  // No: an existing file is kept (OutputExists)
  bool progress = false;           // a line on stderr once a write has taken a second
};
// 8-bit images are sRGB-encoded: .exr and .hdr get them decoded to linear floats.
void saveImage(const std::filesystem::path& file, const ImageRGBA8& image, const ImageWriteOptions& options = {});
// Linear light: written as-is to .exr (32-bit float) and .hdr; .png and .jpg get toSrgb8's encoding.
void saveImage(const std::filesystem::path& file, const ImageF& linear, const ImageWriteOptions& options = {});

float srgbToLinear(float c);
float linearToSrgb(float c);
ImageRGBA8 toSrgb8(const ImageF& linear);  // clamps to [0,1], encodes sRGB, alpha linear

}  // namespace rtr
