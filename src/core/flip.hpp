#pragma once
// A ꟻLIP-style perceptual image difference (docs/flip.md): how visible the difference between two LDR
// images is to a viewer at a given distance, per pixel in [0, 1]. A colour pipeline (opponent space blurred
// by the eye's contrast sensitivity, then HyAB distance in a perceptually uniform space) and a feature
// pipeline (edges and points of luminance) combined as colour^(1 - feature). Symmetric in its two images.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/image.hpp"

namespace rtr {

struct FlipOptions {
  double ppd = 67.0;     // pixels per degree of visual angle: 67 = a 0.7 m wide 4K monitor seen from 0.7 m
  unsigned threads = 0;  // 0: every core
};

struct FlipStats {
  size_t pixels = 0;                  // pixels summarised
  double mean = 0, p99 = 0, max = 0;  // p99: the value 99 % of the pixels are at or below
};

struct FlipResult {
  uint32_t width = 0, height = 0;
  std::vector<float> error;  // per pixel, row-major, top row first, in [0, 1]
  // Over the pixels where mask (one entry a pixel) is true; every pixel without one.
  FlipStats stats(const std::vector<bool>* mask = nullptr) const;
};

// Linear RGB, alpha ignored; values are clamped to [0, 1] (what an LDR display shows). Throws rtr::Error
// when the sizes differ, an image is empty or its buffer does not match its size, or a value is NaN or
// infinite (naming the image and the pixel).
FlipResult flip(const ImageF& a, const ImageF& b, const FlipOptions& options = {});
// The two pipelines alone, per pixel in [0, 1] (flip's error is colour^(1 − feature)): what each adds.
std::vector<float> flipColourError(const ImageF& a, const ImageF& b, const FlipOptions& options = {});
std::vector<float> flipFeatureError(const ImageF& a, const ImageF& b, const FlipOptions& options = {});
// sRGB-encoded 8-bit images (PNG files as they are), alpha ignored.
FlipResult flip(const ImageRGBA8& a, const ImageRGBA8& b, const FlipOptions& options = {});

// The error map for looking at: 0 black through purple, red and orange to 1 pale yellow.
ImageRGBA8 flipHeatMap(const FlipResult& result);

}  // namespace rtr
