#include "core/compare.hpp"

#include <algorithm>
#include <cstdlib>
#include <string>

#include "core/error.hpp"

namespace rtr {
namespace {

void checkSizes(const ImageRGBA8& test, const ImageRGBA8& ref) {
  auto dims = [](const ImageRGBA8& i) { return std::to_string(i.width) + "x" + std::to_string(i.height); };
  if (test.width != ref.width || test.height != ref.height)
    throw Error("image compare: test is " + dims(test) + ", reference is " + dims(ref));
  for (const ImageRGBA8* i : {&test, &ref})
    if (i->pixels.size() != size_t(i->width) * i->height * 4)
      throw Error("image compare: " + std::to_string(i->pixels.size()) + " bytes for a " + dims(*i) + " image");
}

int maxChannelError(const uint8_t* a, const uint8_t* b) {
  int e = 0;
  for (int c = 0; c < 4; ++c) e = std::max(e, std::abs(int(a[c]) - int(b[c])));
  return e;
}

}  // namespace

CompareResult compareEdgeTolerant(const ImageRGBA8& test, const ImageRGBA8& ref, int threshold) {
  checkSizes(test, ref);
  const uint32_t w = ref.width, h = ref.height;
  CompareResult r;
  r.width = w;
  r.height = h;
  r.errorMap = ImageRGBA8{w, h, std::vector<uint8_t>(size_t(w) * h * 4)};
  const double greyScale = 255.0 / std::max(threshold, 1);
  double sumAll = 0, sumPassing = 0;
  int maxAll = 0, maxPassing = 0;
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const uint8_t* t = test.at(x, y);
      bool pass = false;
      for (uint32_t ny = (y ? y - 1 : 0); ny <= std::min(y + 1, h - 1) && !pass; ++ny)
        for (uint32_t nx = (x ? x - 1 : 0); nx <= std::min(x + 1, w - 1) && !pass; ++nx)
          pass = maxChannelError(t, ref.at(nx, ny)) <= threshold;
      const uint8_t* s = ref.at(x, y);
      int pixelSum = 0;
      for (int c = 0; c < 4; ++c) pixelSum += std::abs(int(t[c]) - int(s[c]));
      const int e = maxChannelError(t, s);
      sumAll += pixelSum;
      maxAll = std::max(maxAll, e);
      uint8_t* m = r.errorMap.at(x, y);
      if (pass) {
        sumPassing += pixelSum;
        maxPassing = std::max(maxPassing, e);
        const uint8_t g = uint8_t(std::min(255.0, e * greyScale + 0.5));
        m[0] = m[1] = m[2] = g;
      } else {
        ++r.failingPixels;
        m[0] = 255;
        m[1] = m[2] = 0;
      }
      m[3] = 255;
    }
  const uint64_t n = uint64_t(w) * h, passing = n - r.failingPixels;
  if (n) {
    r.failingFraction = double(r.failingPixels) / double(n);
    r.meanAbsError = sumAll / (4.0 * double(n));
  }
  if (passing) r.meanAbsErrorPassing = sumPassing / (4.0 * double(passing));
  r.maxAbsError = maxAll;
  r.maxAbsErrorPassing = maxPassing;
  return r;
}

std::optional<PixelMismatch> firstMismatch(const ImageRGBA8& test, const ImageRGBA8& ref) {
  checkSizes(test, ref);
  for (uint32_t y = 0; y < ref.height; ++y)
    for (uint32_t x = 0; x < ref.width; ++x)
      if (!std::equal(test.at(x, y), test.at(x, y) + 4, ref.at(x, y))) {
        PixelMismatch d{x, y, {}, {}};
        std::copy_n(test.at(x, y), 4, d.test.begin());
        std::copy_n(ref.at(x, y), 4, d.ref.begin());
        return d;
      }
  return std::nullopt;
}

}  // namespace rtr
