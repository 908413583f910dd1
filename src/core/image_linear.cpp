// Linear-light images read whole as floats, for environments: Radiance .hdr (read here: stb's reader is
// left out of the build, core/stb.cpp) and OpenEXR (tinyexr).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <span>
#include <string_view>

#include <tinyexr.h>

#include "core/error.hpp"
#include "core/image.hpp"
#include "core/input_file.hpp"

namespace rtr {

namespace {

constexpr uint64_t kMaxLinearBytes = uint64_t(1) << 31;  // 2 GiB of file: a 16k×8k float map is 1.5 GiB

// Radiance RGBE: a text header ending in an empty line, the resolution line "-Y H +X W" (rows top first),
// then each row flat (4 bytes a pixel) or run-length coded per channel (a row starts 2 2 W/256 W%256).
ImageF decodeHdr(std::span<const uint8_t> b, const std::string& file) {
  size_t pos = 0;
  auto line = [&]() -> std::string_view {
    const size_t start = pos;
    while (pos < b.size() && b[pos] != '\n') ++pos;
    if (pos >= b.size()) throw fileError(file, "", "Radiance HDR header has no end");
    return {reinterpret_cast<const char*>(b.data()) + start, pos++ - start};
  };
  const std::string_view magic = line();
  if (magic != "#?RADIANCE" && magic != "#?RGBE") throw fileError(file, "", "not a Radiance HDR file (no #?RADIANCE line)");
  for (std::string_view l = line(); !l.empty(); l = line())
    if (l.substr(0, 7) == "FORMAT=" && l != "FORMAT=32-bit_rle_rgbe")
      throw fileError(file, "", "Radiance HDR format '" + std::string(l.substr(7)) + "' is not supported (only 32-bit_rle_rgbe)");
  const std::string res(line());
  int h = 0, w = 0;
  char tail = 0;
  if (std::sscanf(res.c_str(), "-Y %d +X %d%c", &h, &w, &tail) != 2 || w <= 0 || h <= 0 || w > 32768 || h > 32768)
    throw fileError(file, "", "Radiance HDR resolution line '" + res + "' is not '-Y H +X W' with sides 1..32768");
  ImageF out{uint32_t(w), uint32_t(h), std::vector<glm::vec4>(size_t(w) * h)};
  std::vector<uint8_t> row(size_t(w) * 4);
  auto need = [&](size_t n, int y) {
    if (b.size() - pos < n) throw fileError(file, "row " + std::to_string(y), "Radiance HDR data ends early");
  };
  for (int y = 0; y < h; ++y) {
    need(4, y);
    if (w >= 8 && w < 32768 && b[pos] == 2 && b[pos + 1] == 2 && ((b[pos + 2] << 8) | b[pos + 3]) == w) {
      pos += 4;
      for (int c = 0; c < 4; ++c)
        for (int x = 0; x < w;) {
          need(1, y);
          int n = b[pos++];
          const bool run = n > 128;
          if (run) n -= 128;
          if (n == 0 || n > w - x) throw fileError(file, "row " + std::to_string(y), "Radiance HDR run overflows the row");
          need(run ? 1 : size_t(n), y);
          for (int i = 0; i < n; ++i) row[size_t(x + i) * 4 + c] = run ? b[pos] : b[pos + i];
          pos += run ? 1 : size_t(n);
          x += n;
        }
    } else {
      need(row.size(), y);
      std::memcpy(row.data(), &b[pos], row.size());
      pos += row.size();
    }
    for (int x = 0; x < w; ++x) {
      const uint8_t* p = &row[size_t(x) * 4];
      const float f = p[3] ? std::ldexp(1.0f, int(p[3]) - (128 + 8)) : 0.0f;
      out.at(uint32_t(x), uint32_t(y)) = {p[0] * f, p[1] * f, p[2] * f, 1.0f};
    }
  }
  return out;
}

}  // namespace

ImageF loadLinearImage(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  const MappedFile mapped(file, "environment map");       // a regular file, or refused without blocking
  const std::span<const uint8_t> bytes = mapped.bytes();  // decoded in place, not copied
  if (bytes.size() > kMaxLinearBytes) throw fileError(file.string(), "", "larger than 2 GiB");
  ImageF out;
  if (ext == ".exr") {
    float* rgba = nullptr;
    int w = 0, h = 0;
    const char* err = nullptr;
    if (LoadEXRFromMemory(&rgba, &w, &h, bytes.data(), bytes.size(), &err) != TINYEXR_SUCCESS) {
      const std::string why = err ? err : "not an OpenEXR image";
      FreeEXRErrorMessage(err);
      throw fileError(file.string(), "", "cannot decode OpenEXR: " + why);
    }
    out = {uint32_t(w), uint32_t(h), std::vector<glm::vec4>(size_t(w) * h)};
    for (size_t i = 0; i < out.pixels.size(); ++i)
      out.pixels[i] = {rgba[i * 4], rgba[i * 4 + 1], rgba[i * 4 + 2], rgba[i * 4 + 3]};
    std::free(rgba);
  } else if (ext == ".hdr") {
    out = decodeHdr(bytes, file.string());
  } else {
    throw fileError(file.string(), "", "not a linear image (.hdr or .exr)");
  }
  return out;
}

}  // namespace rtr
