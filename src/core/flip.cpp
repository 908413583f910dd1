#include "core/flip.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/vec3.hpp>

#include "core/error.hpp"
#include "core/parallel.hpp"

namespace rtr {
namespace {

using Plane = std::vector<float>;
using Kernel = std::vector<float>;  // 2r + 1 taps, the centre at r

constexpr double kPi = std::numbers::pi;
// The published model's constants (docs/flip.md): colour error exponent, the compression's knee (a share
// of the largest error) and the value it maps to; the feature detectors' width in degrees and exponent.
constexpr double kQc = 0.7, kPc = 0.4, kPt = 0.95, kFeatureWidthDeg = 0.082, kQf = 0.5;

// Contrast sensitivity of one opponent channel as a sum of Gaussians in frequency: a1 e^(-b1 f²) + a2 e^(-b2 f²)
// (f in cycles per degree). Low-pass for all three: fine detail in colour is invisible, in luminance less so.
struct Csf {
  double a1, b1, a2, b2;
};
constexpr Csf kCsfY{1.0, 0.0047, 0.0, 1e-5}, kCsfCx{1.0, 0.0053, 0.0, 1e-5}, kCsfCz{34.1, 0.04, 13.5, 0.025};

// Linear sRGB (D65) to CIE XYZ, rows as usually written; the white point is what (1, 1, 1) maps to.
const glm::dmat3 kRgbToXyz = glm::transpose(glm::dmat3(0.4124564, 0.3575761, 0.1804375,  //
                                                       0.2126729, 0.7151522, 0.0721750,  //
                                                       0.0193339, 0.1191920, 0.9503041));
const glm::dmat3 kXyzToRgb = glm::inverse(kRgbToXyz);
const glm::dvec3 kWhite = kRgbToXyz * glm::dvec3(1.0);

// YCxCz: CIELAB without its cube root, so linear in XYZ and fit for filtering (a blur of it is a blur of
// the light). Y' = 116 y − 16, Cx = 500 (x − y), Cz = 200 (y − z) with x = X / Xw etc.
glm::dvec3 rgbToYcxcz(glm::dvec3 rgb) {
  const glm::dvec3 n = kRgbToXyz * rgb / kWhite;
  return {116.0 * n.y - 16.0, 500.0 * (n.x - n.y), 200.0 * (n.y - n.z)};
}
glm::dvec3 ycxczToRgb(glm::dvec3 c) {
  const double y = (c.x + 16.0) / 116.0;
  return kXyzToRgb * (glm::dvec3(c.y / 500.0 + y, y, y - c.z / 200.0) * kWhite);
}

// CIELAB (perceptually uniform: equal distances look about equally different), with the Hunt effect:
// colourfulness fades as light dims, so a and b are scaled by L / 100.
glm::dvec3 huntLab(glm::dvec3 rgb) {
  const glm::dvec3 n = kRgbToXyz * rgb / kWhite;
  auto f = [](double t) {
    constexpr double d = 6.0 / 29.0;
    return t > d * d * d ? std::cbrt(t) : t / (3.0 * d * d) + 4.0 / 29.0;
  };
  const double L = 116.0 * f(n.y) - 16.0;
  return {L, 0.01 * L * 500.0 * (f(n.x) - f(n.y)), 0.01 * L * 200.0 * (f(n.y) - f(n.z))};
}

// HyAB: city-block in lightness, Euclidean in colour: better than ΔE for large differences.
double hyab(glm::dvec3 p, glm::dvec3 q) { return std::abs(p.x - q.x) + std::hypot(p.y - q.y, p.z - q.z); }

// The largest colour error, between pure green and pure blue, raised like every error.
const double kCmax = std::pow(hyab(huntLab({0, 1, 0}), huntLab({0, 0, 1})), kQc);

// Errors up to kPc of the largest fill most of [0, 1]; the rare larger ones share the rest.
double compress(double e) {
  const double knee = kPc * kCmax;
  return e < knee ? e * kPt / knee : kPt + (e - knee) / (kCmax - knee) * (1.0 - kPt);
}

// Taps in double: a detector narrower than a pixel has side taps far below float's range (e^−297 at 1 ppd).
std::vector<double> gaussian(double sigmaPx) {
  const int r = std::max(1, int(std::ceil(3.0 * sigmaPx)));
  std::vector<double> k(2 * r + 1);
  for (int x = -r; x <= r; ++x) k[x + r] = std::exp(-x * x / (2.0 * sigmaPx * sigmaPx));
  return k;
}
Kernel normalised(const std::vector<double>& k) {
  double s = 0;
  for (double v : k) s += v;
  Kernel out(k.size());
  for (size_t i = 0; i < k.size(); ++i) out[i] = float(k[i] / s);
  return out;
}
// Positive taps scaled to sum 1 and negative ones to −1: a detector answers 0 to a flat image, and its
// response to an image in [0, 1] is within [−1, 1]. One with no taps on a side (narrower than a pixel) sees
// nothing: all 0.
Kernel balanced(const std::vector<double>& k) {
  double pos = 0, neg = 0;
  for (double v : k) (v > 0 ? pos : neg) += v;
  Kernel out(k.size(), 0.0f);
  if (pos > 0 && neg < 0)
    for (size_t i = 0; i < k.size(); ++i) out[i] = float(k[i] > 0 ? k[i] / pos : k[i] / -neg);
  return out;
}

// `in` correlated with kx along rows, then ky along columns; outside the image the border pixel repeats.
// Each tap is added to a whole row at once (the loops the compiler vectorises); only the border clamps.
Plane convolve(const Plane& in, uint32_t w, uint32_t h, const Kernel& kx, const Kernel& ky, unsigned threads) {
  Plane tmp(in.size()), out(in.size());
  const int rx = int(kx.size() / 2), ry = int(ky.size() / 2), iw = int(w), ih = int(h);
  constexpr int kRows = 16;  // rows a piece of work
  const size_t pieces = (h + kRows - 1) / kRows;
  parallelFor(pieces, threads, [&](size_t p) {
    for (int y = int(p) * kRows; y < std::min(ih, (int(p) + 1) * kRows); ++y) {
      const float* src = &in[size_t(y) * w];
      float* dst = &tmp[size_t(y) * w];
      for (int k = -rx; k <= rx; ++k) {
        const float c = kx[k + rx];
        const int lo = std::clamp(-k, 0, iw), hi = std::clamp(iw - k, lo, iw);  // x + k inside for x in [lo, hi)
        for (int x = 0; x < lo; ++x) dst[x] += c * src[0];
        for (int x = lo; x < hi; ++x) dst[x] += c * src[x + k];
        for (int x = hi; x < iw; ++x) dst[x] += c * src[iw - 1];
      }
    }
  });
  parallelFor(pieces, threads, [&](size_t p) {
    for (int y = int(p) * kRows; y < std::min(ih, (int(p) + 1) * kRows); ++y) {
      float* dst = &out[size_t(y) * w];
      for (int k = -ry; k <= ry; ++k) {
        const float c = ky[k + ry];
        const float* src = &tmp[size_t(std::clamp(y + k, 0, ih - 1)) * w];
        for (int x = 0; x < iw; ++x) dst[x] += c * src[x];
      }
    }
  });
  return out;
}

// The CSF's spatial filter, normalised to sum 1: each Gaussian term of the frequency model is a Gaussian in
// space (2-D transform of a e^(−b f²): a π / b · e^(−π² r² / b), r in degrees), so the filter is a weighted
// sum of separable blurs.
Plane csfFilter(const Plane& in, uint32_t w, uint32_t h, const Csf& c, double ppd, unsigned threads) {
  Plane out(in.size(), 0.0f);
  const double terms[2][2] = {{c.a1, c.b1}, {c.a2, c.b2}};
  double weights[2] = {0, 0}, total = 0;
  Kernel kernels[2];
  for (int i = 0; i < 2; ++i) {
    if (terms[i][0] == 0) continue;
    const std::vector<double> g = gaussian(std::sqrt(terms[i][1] / (2.0 * kPi * kPi)) * ppd);
    double s = 0;
    for (double v : g) s += v;
    weights[i] = terms[i][0] * kPi / terms[i][1] * s * s;  // the term's sum over the 2-D kernel
    total += weights[i];
    kernels[i] = normalised(g);
  }
  for (int i = 0; i < 2; ++i) {
    if (weights[i] == 0) continue;
    const Plane p = convolve(in, w, h, kernels[i], kernels[i], threads);
    for (size_t j = 0; j < out.size(); ++j) out[j] += float(weights[i] / total) * p[j];
  }
  return out;
}

struct Opponent {
  Plane y, cx, cz;  // YCxCz
};

Opponent toOpponent(const ImageF& img, const char* which) {
  Opponent o{Plane(img.pixels.size()), Plane(img.pixels.size()), Plane(img.pixels.size())};
  for (size_t i = 0; i < img.pixels.size(); ++i) {
    const glm::vec4 p = img.pixels[i];
    if (!std::isfinite(p.r) || !std::isfinite(p.g) || !std::isfinite(p.b))
      throw Error(std::string("ꟻLIP: the ") + which + " image has a value that is not finite at pixel (" +
                  std::to_string(i % img.width) + ", " + std::to_string(i / img.width) + ")");
    const glm::dvec3 c = rgbToYcxcz(glm::clamp(glm::dvec3(p.r, p.g, p.b), 0.0, 1.0));
    o.y[i] = float(c.x);
    o.cx[i] = float(c.y);
    o.cz[i] = float(c.z);
  }
  return o;
}

// Edge and point strength of luminance y = Y / Yw in [0, 1]: the gradient's magnitude under the first
// derivative of a Gaussian, and under the second (a dot or a thin line), at the detectors' width.
struct Features {
  Plane edge, point;
};
Features features(const Plane& y, uint32_t w, uint32_t h, double ppd, unsigned threads) {
  const double sigma = 0.5 * kFeatureWidthDeg * ppd;
  const std::vector<double> gd = gaussian(sigma);
  std::vector<double> first = gd, second = gd;
  const int r = int(gd.size() / 2);
  for (int x = -r; x <= r; ++x) {
    first[x + r] = -x / (sigma * sigma) * gd[x + r];
    second[x + r] = (x * x / (sigma * sigma) - 1.0) / (sigma * sigma) * gd[x + r];
  }
  const Kernel g = normalised(gd), d1 = balanced(first), d2 = balanced(second);
  Features f{convolve(y, w, h, d1, g, threads), convolve(y, w, h, d2, g, threads)};
  const Plane ey = convolve(y, w, h, g, d1, threads), py = convolve(y, w, h, g, d2, threads);
  for (size_t i = 0; i < y.size(); ++i) {
    f.edge[i] = std::hypot(f.edge[i], ey[i]);
    f.point[i] = std::hypot(f.point[i], py[i]);
  }
  return f;
}

// n: the buffers' element counts, `per` a pixel.
void checkSizes(uint32_t wa, uint32_t ha, size_t na, uint32_t wb, uint32_t hb, size_t nb, size_t per) {
  auto dims = [](uint32_t w, uint32_t h) { return std::to_string(w) + "x" + std::to_string(h); };
  if (wa != wb || ha != hb) throw Error("ꟻLIP: the images differ in size: " + dims(wa, ha) + " and " + dims(wb, hb));
  if (wa == 0 || ha == 0) throw Error("ꟻLIP: the images are empty (" + dims(wa, ha) + ")");
  if (na != size_t(wa) * ha * per || nb != size_t(wb) * hb * per)
    throw Error("ꟻLIP: a pixel buffer does not match its image's size " + dims(wa, ha));
}

// The colour pipeline: what each image looks like at this distance, compared in a perceptually uniform space.
std::vector<float> colourError(const Opponent& oa, const Opponent& ob, uint32_t w, uint32_t h, const FlipOptions& o) {
  const double ppd = o.ppd;
  const unsigned t = o.threads;
  const Opponent fa{csfFilter(oa.y, w, h, kCsfY, ppd, t), csfFilter(oa.cx, w, h, kCsfCx, ppd, t),
                    csfFilter(oa.cz, w, h, kCsfCz, ppd, t)};
  const Opponent fb{csfFilter(ob.y, w, h, kCsfY, ppd, t), csfFilter(ob.cx, w, h, kCsfCx, ppd, t),
                    csfFilter(ob.cz, w, h, kCsfCz, ppd, t)};
  std::vector<float> e(oa.y.size());
  for (size_t i = 0; i < e.size(); ++i) {
    // Filtered colours can leave the gamut: clamped back, as the display would.
    auto lab = [i](const Opponent& f) { return huntLab(glm::clamp(ycxczToRgb({f.y[i], f.cx[i], f.cz[i]}), 0.0, 1.0)); };
    e[i] = float(compress(std::pow(hyab(lab(fa), lab(fb)), kQc)));
  }
  return e;
}

// The feature pipeline, on luminance before filtering (an edge the blur would soften is still seen as one).
std::vector<float> featureError(const Opponent& oa, const Opponent& ob, uint32_t w, uint32_t h, const FlipOptions& o) {
  auto luminance = [](const Plane& yPrime) {
    Plane y(yPrime.size());
    for (size_t i = 0; i < y.size(); ++i) y[i] = (yPrime[i] + 16.0f) / 116.0f;
    return y;
  };
  const Features fa = features(luminance(oa.y), w, h, o.ppd, o.threads), fb = features(luminance(ob.y), w, h, o.ppd, o.threads);
  std::vector<float> e(oa.y.size());
  for (size_t i = 0; i < e.size(); ++i) {
    const double d = std::max(std::abs(fa.edge[i] - fb.edge[i]), std::abs(fa.point[i] - fb.point[i]));
    e[i] = float(std::min(1.0, std::pow(d / std::sqrt(2.0), kQf)));
  }
  return e;
}

std::pair<Opponent, Opponent> opponents(const ImageF& a, const ImageF& b, const FlipOptions& options) {
  checkSizes(a.width, a.height, a.pixels.size(), b.width, b.height, b.pixels.size(), 1);
  if (!(options.ppd > 0) || !std::isfinite(options.ppd)) throw Error("ꟻLIP: pixels per degree must be > 0");
  return {toOpponent(a, "first"), toOpponent(b, "second")};
}

}  // namespace

std::vector<float> flipColourError(const ImageF& a, const ImageF& b, const FlipOptions& options) {
  const auto [oa, ob] = opponents(a, b, options);
  return colourError(oa, ob, a.width, a.height, options);
}

std::vector<float> flipFeatureError(const ImageF& a, const ImageF& b, const FlipOptions& options) {
  const auto [oa, ob] = opponents(a, b, options);
  return featureError(oa, ob, a.width, a.height, options);
}

FlipResult flip(const ImageF& a, const ImageF& b, const FlipOptions& options) {
  const auto [oa, ob] = opponents(a, b, options);
  FlipResult r{a.width, a.height, colourError(oa, ob, a.width, a.height, options)};
  const std::vector<float> feature = featureError(oa, ob, a.width, a.height, options);
  // A difference at an edge or a point is seen more: the colour error raised to a power below 1.
  // No colour difference is no error (0^0 would be 1).
  for (size_t i = 0; i < r.error.size(); ++i)
    if (r.error[i] > 0) r.error[i] = std::pow(r.error[i], 1.0f - feature[i]);
  return r;
}

FlipResult flip(const ImageRGBA8& a, const ImageRGBA8& b, const FlipOptions& options) {
  checkSizes(a.width, a.height, a.pixels.size(), b.width, b.height, b.pixels.size(), 4);
  float linear[256];
  for (int i = 0; i < 256; ++i) linear[i] = srgbToLinear(i / 255.0f);
  auto toLinear = [&](const ImageRGBA8& img) {
    ImageF f{img.width, img.height, std::vector<glm::vec4>(size_t(img.width) * img.height)};
    for (size_t i = 0; i < f.pixels.size(); ++i)
      f.pixels[i] = {linear[img.pixels[4 * i]], linear[img.pixels[4 * i + 1]], linear[img.pixels[4 * i + 2]], 1.0f};
    return f;
  };
  return flip(toLinear(a), toLinear(b), options);
}

FlipStats FlipResult::stats(const std::vector<bool>* mask) const {
  std::vector<float> v;
  v.reserve(error.size());
  for (size_t i = 0; i < error.size(); ++i)
    if (!mask || (i < mask->size() && (*mask)[i])) v.push_back(error[i]);
  FlipStats s{v.size()};
  if (v.empty()) return s;
  double total = 0;
  for (float e : v) total += e;
  s.mean = total / double(v.size());
  s.max = *std::max_element(v.begin(), v.end());
  const size_t rank = size_t(std::ceil(0.99 * double(v.size()))) - 1;
  std::nth_element(v.begin(), v.begin() + rank, v.end());
  s.p99 = v[rank];
  return s;
}

ImageRGBA8 flipHeatMap(const FlipResult& r) {
  // Brightness rises with the error, so the map reads in grey too; hue separates small from large.
  constexpr float stops[5][3] = {{0, 0, 0}, {0.35f, 0.05f, 0.5f}, {0.85f, 0.15f, 0.3f}, {1.0f, 0.6f, 0.1f}, {1.0f, 1.0f, 0.75f}};
  ImageRGBA8 img{r.width, r.height, std::vector<uint8_t>(r.error.size() * 4)};
  for (size_t i = 0; i < r.error.size(); ++i) {
    const float t = std::clamp(r.error[i], 0.0f, 1.0f) * 4.0f;
    const int k = std::min(3, int(t));
    for (int c = 0; c < 3; ++c)
      img.pixels[4 * i + c] = uint8_t(std::lround(255.0f * (stops[k][c] + (t - k) * (stops[k + 1][c] - stops[k][c]))));
    img.pixels[4 * i + 3] = 255;
  }
  return img;
}

}  // namespace rtr
