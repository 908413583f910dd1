#include "png.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

#include <stb_image_write.h>  // the implementation is compiled once, in rtr_core

namespace scenegen {
namespace {

uint32_t crc32(const uint8_t* p, size_t n, uint32_t c = 0xFFFFFFFFu) {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t v = i;
      for (int k = 0; k < 8; ++k) v = (v & 1) ? 0xEDB88320u ^ (v >> 1) : v >> 1;
      t[i] = v;
    }
    return t;
  }();
  for (size_t i = 0; i < n; ++i) c = table[(c ^ p[i]) & 0xFF] ^ (c >> 8);
  return c;
}

void be32(std::vector<uint8_t>& o, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) o.push_back(uint8_t(v >> s));
}

// zlib stream of stored (uncompressed) deflate blocks: these images are small, and this keeps the
// encoder a few lines long.
std::vector<uint8_t> zlibStored(const std::vector<uint8_t>& d) {
  std::vector<uint8_t> o = {0x78, 0x01};
  size_t i = 0;
  do {
    const size_t n = std::min<size_t>(65535, d.size() - i);
    o.push_back(i + n == d.size() ? 1 : 0);
    o.insert(o.end(), {uint8_t(n), uint8_t(n >> 8), uint8_t(~n), uint8_t(~n >> 8)});
    o.insert(o.end(), d.begin() + i, d.begin() + i + n);
    i += n;
  } while (i < d.size());
  uint32_t a = 1, b = 0;
  for (uint8_t c : d) {
    a = (a + c) % 65521;
    b = (b + a) % 65521;
  }
  be32(o, (b << 16) | a);
  return o;
}

void chunk(std::vector<uint8_t>& o, const char* type, const std::vector<uint8_t>& data) {
  be32(o, uint32_t(data.size()));
  const size_t start = o.size();
  o.insert(o.end(), type, type + 4);
  o.insert(o.end(), data.begin(), data.end());
  be32(o, crc32(o.data() + start, o.size() - start) ^ 0xFFFFFFFFu);
}

// rows: already packed scanlines without filter bytes.
void writeRaw(const std::filesystem::path& file, int w, int h, uint8_t depth, uint8_t colourType,
              const std::vector<uint8_t>& rows, size_t stride, const std::vector<uint8_t>* plte) {
  std::vector<uint8_t> filtered;
  for (int y = 0; y < h; ++y) {
    filtered.push_back(0);
    filtered.insert(filtered.end(), rows.begin() + y * stride, rows.begin() + (y + 1) * stride);
  }
  std::vector<uint8_t> o = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  std::vector<uint8_t> ihdr;
  be32(ihdr, uint32_t(w));
  be32(ihdr, uint32_t(h));
  ihdr.insert(ihdr.end(), {depth, colourType, 0, 0, 0});
  chunk(o, "IHDR", ihdr);
  if (plte) chunk(o, "PLTE", *plte);
  chunk(o, "IDAT", zlibStored(filtered));
  chunk(o, "IEND", {});
  std::FILE* f = std::fopen(file.c_str(), "wb");
  if (!f || std::fwrite(o.data(), 1, o.size(), f) != o.size()) throw std::runtime_error("cannot write " + file.string());
  std::fclose(f);
}

}  // namespace

void writePng8(const std::filesystem::path& file, int w, int h, int channels, const std::vector<uint8_t>& pixels) {
  if (!stbi_write_png(file.c_str(), w, h, channels, pixels.data(), w * channels))
    throw std::runtime_error("cannot write " + file.string());
}

void writePalettePng(const std::filesystem::path& file, int w, int h, const std::vector<uint8_t>& indices,
                     const std::vector<uint8_t>& paletteRgb) {
  writeRaw(file, w, h, 8, 3, indices, size_t(w), &paletteRgb);
}

void writeBitPng(const std::filesystem::path& file, int w, int h, const std::vector<uint8_t>& bits) {
  const size_t stride = (size_t(w) + 7) / 8;
  std::vector<uint8_t> rows(stride * h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (bits[size_t(y) * w + x]) rows[y * stride + x / 8] |= uint8_t(0x80 >> (x % 8));
  writeRaw(file, w, h, 1, 0, rows, stride, nullptr);
}

}  // namespace scenegen
