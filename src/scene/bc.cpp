#include "scene/bc.hpp"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>

namespace rtr::bc {
namespace {

// 5- and 6-bit endpoints widen to 8 bits by repeating their high bits (Vulkan's data format specification).
int expand5(int x) { return (x << 3) | (x >> 2); }
int expand6(int x) { return (x << 2) | (x >> 4); }
void unpack565(uint16_t c, int out[3]) {
  out[0] = expand5(c >> 11);
  out[1] = expand6((c >> 5) & 63);
  out[2] = expand5(c & 31);
}

// Colours 2 and 3 of a four-colour block are c0 and c1 mixed 2:1 and 1:2, rounded to nearest.
void palette4(uint16_t c0, uint16_t c1, int p[4][3]) {
  unpack565(c0, p[0]);
  unpack565(c1, p[1]);
  for (int k = 0; k < 3; ++k) {
    p[2][k] = (2 * p[0][k] + p[1][k] + 1) / 3;
    p[3][k] = (p[0][k] + 2 * p[1][k] + 1) / 3;
  }
}

struct Colour {
  uint16_t c0 = 0, c1 = 0;
  uint32_t indices = 0;
  uint32_t error = UINT32_MAX;  // summed squared error over the 16 texels' RGB
};

// The block for two endpoints: c0 > c1 (four-colour mode in BC1; swapping the endpoints swaps colours 2 and 3,
// so nothing is lost), each texel the nearest colour. Equal endpoints: every texel index 0 (the first minimum).
Colour fit(const int px[16][3], uint16_t c0, uint16_t c1) {
  Colour c{std::max(c0, c1), std::min(c0, c1)};
  int p[4][3];
  palette4(c.c0, c.c1, p);
  c.error = 0;
  for (int i = 0; i < 16; ++i) {
    int best = 0, bestD = INT_MAX;
    for (int k = 0; k < 4; ++k) {
      const int dr = px[i][0] - p[k][0], dg = px[i][1] - p[k][1], db = px[i][2] - p[k][2];
      const int d = dr * dr + dg * dg + db * db;
      if (d < bestD) bestD = d, best = k;
    }
    c.indices |= uint32_t(best) << (2 * i);
    c.error += uint32_t(bestD);
  }
  return c;
}

uint16_t quantize(const float c[3]) {
  auto q = [](float v, int max) { return std::clamp(int(std::lround(v * float(max) / 255.0f)), 0, max); };
  return uint16_t(q(c[0], 31) << 11 | q(c[1], 63) << 5 | q(c[2], 31));
}

// For each 8-bit value, the endpoints a, b (5 or 6 bits) whose colour 2, (2a + b) / 3, comes nearest: a flat
// block's colour reproduced within a step of the finer grid the mixes make.
struct Pair {
  uint8_t a = 0, b = 0;
};
std::array<Pair, 256> singleTable(int bits) {
  std::array<Pair, 256> t;
  const int max = (1 << bits) - 1;
  for (int v = 0; v < 256; ++v) {
    int bestD = INT_MAX;
    for (int a = 0; a <= max; ++a)
      for (int b = 0; b <= max; ++b) {
        const int ea = bits == 5 ? expand5(a) : expand6(a), eb = bits == 5 ? expand5(b) : expand6(b);
        const int d = std::abs((2 * ea + eb + 1) / 3 - v);
        if (d < bestD) bestD = d, t[size_t(v)] = {uint8_t(a), uint8_t(b)};
      }
  }
  return t;
}

Colour single(const int px[16][3], const int colour[3]) {
  static const std::array<Pair, 256> t5 = singleTable(5), t6 = singleTable(6);
  const Pair r = t5[size_t(colour[0])], g = t6[size_t(colour[1])], b = t5[size_t(colour[2])];
  return fit(px, uint16_t(r.a << 11 | g.a << 5 | b.a), uint16_t(r.b << 11 | g.b << 5 | b.b));
}

// The endpoints that minimise the squared error for the texels' current indices (each texel a fixed mix of
// the two): a 2x2 system per channel. False when every texel has the same mix.
bool leastSquares(const int px[16][3], uint32_t indices, float e0[3], float e1[3]) {
  static constexpr float kWeight[4] = {1.0f, 0.0f, 2.0f / 3.0f, 1.0f / 3.0f};  // of c0, per index
  float aa = 0, ab = 0, bb = 0, ax[3] = {}, bx[3] = {};
  for (int i = 0; i < 16; ++i) {
    const float a = kWeight[(indices >> (2 * i)) & 3], b = 1.0f - a;
    aa += a * a, ab += a * b, bb += b * b;
    for (int k = 0; k < 3; ++k) ax[k] += a * float(px[i][k]), bx[k] += b * float(px[i][k]);
  }
  const float det = aa * bb - ab * ab;
  if (det < 1e-3f) return false;
  for (int k = 0; k < 3; ++k) {
    e0[k] = (bb * ax[k] - ab * bx[k]) / det;
    e1[k] = (aa * bx[k] - ab * ax[k]) / det;
  }
  return true;
}

// BC4's values: red_0, red_1, then six in sevenths between them (red_0 > red_1), or four in fifths, 0 and 255.
void palette8(int r0, int r1, int v[8]) {
  v[0] = r0;
  v[1] = r1;
  if (r0 > r1)
    for (int i = 1; i < 7; ++i) v[i + 1] = ((7 - i) * r0 + i * r1 + 3) / 7;
  else {
    for (int i = 1; i < 5; ++i) v[i + 1] = ((5 - i) * r0 + i * r1 + 2) / 5;
    v[6] = 0;
    v[7] = 255;
  }
}

struct Channel {
  int r0 = 0, r1 = 0;
  uint64_t indices = 0;
  uint32_t error = UINT32_MAX;
};

Channel fitChannel(const int t[16], int r0, int r1) {
  Channel c{r0, r1};
  int v[8];
  palette8(r0, r1, v);
  c.error = 0;
  for (int i = 0; i < 16; ++i) {
    int best = 0, bestD = INT_MAX;
    for (int k = 0; k < 8; ++k) {
      const int d = (t[i] - v[k]) * (t[i] - v[k]);
      if (d < bestD) bestD = d, best = k;
    }
    c.indices |= uint64_t(best) << (3 * i);
    c.error += uint32_t(bestD);
  }
  return c;
}

}  // namespace

void encodeColour(const uint8_t rgba[64], uint8_t block[8]) {
  int px[16][3], lo[3] = {255, 255, 255}, hi[3] = {0, 0, 0};
  float mean[3] = {};
  for (int i = 0; i < 16; ++i)
    for (int k = 0; k < 3; ++k) {
      px[i][k] = rgba[4 * i + k];
      lo[k] = std::min(lo[k], px[i][k]);
      hi[k] = std::max(hi[k], px[i][k]);
      mean[k] += float(px[i][k]) / 16.0f;
    }
  const int rounded[3] = {int(std::lround(mean[0])), int(std::lround(mean[1])), int(std::lround(mean[2]))};
  Colour best = single(px, rounded);  // a flat block's colour within 1 per channel
  if (best.error > 0 && (lo[0] < hi[0] || lo[1] < hi[1] || lo[2] < hi[2])) {
    // The principal axis of the texels (power iteration on their covariance, from the box's diagonal), the
    // endpoints where the texels' projections end, then the endpoints refit to the indices while that helps.
    float cov[6] = {};
    for (int i = 0; i < 16; ++i) {
      const float d[3] = {float(px[i][0]) - mean[0], float(px[i][1]) - mean[1], float(px[i][2]) - mean[2]};
      cov[0] += d[0] * d[0], cov[1] += d[0] * d[1], cov[2] += d[0] * d[2];
      cov[3] += d[1] * d[1], cov[4] += d[1] * d[2], cov[5] += d[2] * d[2];
    }
    float axis[3] = {float(hi[0] - lo[0]), float(hi[1] - lo[1]), float(hi[2] - lo[2])};
    for (int it = 0; it < 6; ++it) {
      const float w[3] = {cov[0] * axis[0] + cov[1] * axis[1] + cov[2] * axis[2],
                          cov[1] * axis[0] + cov[3] * axis[1] + cov[4] * axis[2],
                          cov[2] * axis[0] + cov[4] * axis[1] + cov[5] * axis[2]};
      const float m = std::max({std::abs(w[0]), std::abs(w[1]), std::abs(w[2])});
      if (m < 1e-6f) break;
      for (int k = 0; k < 3; ++k) axis[k] = w[k] / m;
    }
    const float len = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    for (float& a : axis) a /= len;  // len > 0: the diagonal is not zero when the block is not flat
    float tmin = 1e9f, tmax = -1e9f;
    for (int i = 0; i < 16; ++i) {
      const float t =
          (float(px[i][0]) - mean[0]) * axis[0] + (float(px[i][1]) - mean[1]) * axis[1] + (float(px[i][2]) - mean[2]) * axis[2];
      tmin = std::min(tmin, t), tmax = std::max(tmax, t);
    }
    float e0[3], e1[3];
    for (int k = 0; k < 3; ++k) e0[k] = mean[k] + axis[k] * tmax, e1[k] = mean[k] + axis[k] * tmin;
    Colour c = fit(px, quantize(e0), quantize(e1));
    for (int it = 0; it < 3 && c.error > 0; ++it) {
      if (c.error < best.error) best = c;
      if (!leastSquares(px, c.indices, e0, e1)) break;
      const Colour next = fit(px, quantize(e0), quantize(e1));
      if (next.error >= c.error) break;
      c = next;
    }
    if (c.error < best.error) best = c;
  }
  block[0] = uint8_t(best.c0), block[1] = uint8_t(best.c0 >> 8);
  block[2] = uint8_t(best.c1), block[3] = uint8_t(best.c1 >> 8);
  for (int b = 0; b < 4; ++b) block[4 + b] = uint8_t(best.indices >> (8 * b));
}

void encodeChannel(const uint8_t texels[16], uint8_t block[8]) {
  int t[16], lo = 255, hi = 0, innerLo = 255, innerHi = 0;
  for (int i = 0; i < 16; ++i) {
    t[i] = texels[i];
    lo = std::min(lo, t[i]), hi = std::max(hi, t[i]);
    if (t[i] != 0 && t[i] != 255) innerLo = std::min(innerLo, t[i]), innerHi = std::max(innerHi, t[i]);
  }
  // Eight values between the extremes (the error at most (hi − lo) / 14), refit to the indices while that
  // helps; where the block holds 0 or 255, also six values between the others plus 0 and 255 exactly.
  Channel best = fitChannel(t, hi, lo);
  for (int it = 0; it < 3 && best.error > 0 && best.r0 > best.r1; ++it) {
    float aa = 0, ab = 0, bb = 0, ax = 0, bx = 0;
    for (int i = 0; i < 16; ++i) {
      const int k = int((best.indices >> (3 * i)) & 7);
      const float a = k == 0 ? 1.0f : k == 1 ? 0.0f : float(8 - k) / 7.0f, b = 1.0f - a;
      aa += a * a, ab += a * b, bb += b * b, ax += a * float(t[i]), bx += b * float(t[i]);
    }
    const float det = aa * bb - ab * ab;
    if (det < 1e-3f) break;
    const int r0 = std::clamp(int(std::lround((bb * ax - ab * bx) / det)), 0, 255);
    const int r1 = std::clamp(int(std::lround((aa * bx - ab * ax) / det)), 0, 255);
    if (r0 == r1) break;
    const Channel next = fitChannel(t, std::max(r0, r1), std::min(r0, r1));
    if (next.error >= best.error) break;
    best = next;
  }
  if ((lo == 0 || hi == 255) && best.error > 0) {
    const Channel six = innerLo <= innerHi ? fitChannel(t, innerLo, innerHi) : fitChannel(t, 0, 0);
    if (six.error < best.error) best = six;
  }
  block[0] = uint8_t(best.r0), block[1] = uint8_t(best.r1);
  for (int b = 0; b < 6; ++b) block[2 + b] = uint8_t(best.indices >> (8 * b));
}

void decodeColour(const uint8_t block[8], bool bc1, uint8_t rgba[64]) {
  const uint16_t c0 = uint16_t(block[0] | block[1] << 8), c1 = uint16_t(block[2] | block[3] << 8);
  int p[4][3];
  palette4(c0, c1, p);
  if (bc1 && c0 <= c1)
    for (int k = 0; k < 3; ++k) p[2][k] = (p[0][k] + p[1][k] + 1) / 2, p[3][k] = 0;
  const uint32_t indices = uint32_t(block[4]) | uint32_t(block[5]) << 8 | uint32_t(block[6]) << 16 | uint32_t(block[7]) << 24;
  for (int i = 0; i < 16; ++i)
    for (int k = 0; k < 3; ++k) rgba[4 * i + k] = uint8_t(p[(indices >> (2 * i)) & 3][k]);
}

void decodeChannel(const uint8_t block[8], uint8_t* texels, int stride) {
  int v[8];
  palette8(block[0], block[1], v);
  uint64_t bits = 0;
  for (int b = 0; b < 6; ++b) bits |= uint64_t(block[2 + b]) << (8 * b);
  for (int i = 0; i < 16; ++i) texels[i * stride] = uint8_t(v[(bits >> (3 * i)) & 7]);
}

}  // namespace rtr::bc
