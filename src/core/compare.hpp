#pragma once
// Image comparison for GPU-vs-CPU reference tests.
#include <array>
#include <cstdint>
#include <optional>

#include "core/image.hpp"

namespace rtr {

struct CompareResult {
  uint32_t width = 0, height = 0;
  uint64_t failingPixels = 0;
  double failingFraction = 0;  // failingPixels / (width * height); 0 for an empty image
  // Absolute per-channel error |test - ref| at the same pixel, over all 4 channels (RGBA).
  double meanAbsError = 0, maxAbsError = 0;                // over all pixels
  double meanAbsErrorPassing = 0, maxAbsErrorPassing = 0;  // over the pixels that pass (0 if none)
  // Failing pixels red (255, 0, 0); the others grey = min(255, e * 255 / max(threshold, 1)) with e the
  // largest channel error at that pixel, so an error of `threshold` is white. Alpha 255.
  ImageRGBA8 errorMap;
};

// A pixel passes if there is one reference pixel among its 3x3 neighbourhood (itself included, clipped
// at the border) whose four channels are all within `threshold` of the test pixel: silhouettes that a
// rasteriser and a ray caster place a sub-pixel apart still pass; a real change does not. The same
// neighbour must match every channel (a colour is compared as a whole). Throws rtr::Error when the
// sizes differ or the pixel buffers do not match the sizes.
CompareResult compareEdgeTolerant(const ImageRGBA8& test, const ImageRGBA8& ref, int threshold);

struct PixelMismatch {
  uint32_t x = 0, y = 0;
  std::array<uint8_t, 4> test{}, ref{};
};

// Bit-exact comparison: the first differing pixel in row-major order (top row first), or none.
// Throws rtr::Error when the sizes differ.
std::optional<PixelMismatch> firstMismatch(const ImageRGBA8& test, const ImageRGBA8& ref);

}  // namespace rtr
