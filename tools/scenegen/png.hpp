#pragma once
// PNG files of every type the Sun Temple textures use (RGB, 8-bit grey, 1-bit grey, palette, RGBA),
// so that loaders meet each one. stb writes the 8-bit kinds; palette and 1-bit are encoded here.
#include <cstdint>
#include <filesystem>
#include <vector>

namespace scenegen {

// `pixels` has `channels` bytes a pixel (1 grey, 3 RGB, 4 RGBA).
void writePng8(const std::filesystem::path& file, int w, int h, int channels, const std::vector<uint8_t>& pixels);
// Palette PNG: one index a pixel into `palette` (RGB triples, at most 256).
void writePalettePng(const std::filesystem::path& file, int w, int h, const std::vector<uint8_t>& indices,
                     const std::vector<uint8_t>& paletteRgb);
// 1-bit grey PNG: one byte a pixel, 0 black, anything else white.
void writeBitPng(const std::filesystem::path& file, int w, int h, const std::vector<uint8_t>& bits);

}  // namespace scenegen
