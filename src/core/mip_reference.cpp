#include "core/mip_reference.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace rtr {
namespace {

// The source texels one destination texel reads along one axis, with their coverage weights.
struct Taps {
  uint32_t first = 0;
  std::vector<double> weights;
};

// weight(i -> x) = |[i*dst, (i+1)*dst) ∩ [x*src, (x+1)*src)| / src, in exact integers (see the header).
std::vector<Taps> axisTaps(uint32_t src, uint32_t dst) {
  std::vector<Taps> taps(dst);
  for (uint64_t x = 0; x < dst; ++x) {
    const uint64_t lo = x * src, hi = (x + 1) * src;
    const uint64_t i0 = lo / dst, i1 = (hi + dst - 1) / dst;  // texels [i0, i1) overlap
    taps[x].first = uint32_t(i0);
    for (uint64_t i = i0; i < i1; ++i) {
      const uint64_t overlap = std::min((i + 1) * dst, hi) - std::max(i * dst, lo);
      taps[x].weights.push_back(double(overlap) / double(src));
    }
  }
  return taps;
}

// Separable box filter from `src` to a dw x dh level: rows first, then columns.
MipLevel boxFilter(const MipLevel& src, uint32_t channels, uint32_t dw, uint32_t dh) {
  const std::vector<Taps> tx = axisTaps(src.width, dw), ty = axisTaps(src.height, dh);
  std::vector<double> rows(size_t(src.height) * dw * channels, 0.0);
  for (uint32_t y = 0; y < src.height; ++y)
    for (uint32_t x = 0; x < dw; ++x)
      for (size_t k = 0; k < tx[x].weights.size(); ++k) {
        const double* s = &src.texels[(size_t(y) * src.width + tx[x].first + k) * channels];
        double* d = &rows[(size_t(y) * dw + x) * channels];
        for (uint32_t c = 0; c < channels; ++c) d[c] += tx[x].weights[k] * s[c];
      }
  MipLevel out{dw, dh, std::vector<double>(size_t(dw) * dh * channels, 0.0)};
  for (uint32_t y = 0; y < dh; ++y)
    for (size_t k = 0; k < ty[y].weights.size(); ++k) {
      const double w = ty[y].weights[k];
      const double* s = &rows[size_t(ty[y].first + k) * dw * channels];
      double* d = &out.texels[size_t(y) * dw * channels];
      for (size_t i = 0; i < size_t(dw) * channels; ++i) d[i] += w * s[i];
    }
  return out;
}

// Channel 3 exists only in RGBA images, where it is alpha: always linear.
bool isSrgbChannel(uint32_t channel, TexelEncoding encoding) { return encoding == TexelEncoding::Srgb && channel < 3; }

}  // namespace

uint32_t mipLevelCount(uint32_t width, uint32_t height) {
  uint32_t m = std::max(width, height), n = 0;
  while (m) {
    ++n;
    m >>= 1;
  }
  return n;
}

uint32_t mipLevelSize(uint32_t size, uint32_t level) { return level >= 32 ? 1 : std::max(1u, size >> level); }

double decodeTexel(uint8_t value, uint32_t channel, TexelEncoding encoding) {
  const double c = value / 255.0;
  if (!isSrgbChannel(channel, encoding)) return c;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

uint8_t encodeTexel(double linear, uint32_t channel, TexelEncoding encoding) {
  double c = std::clamp(linear, 0.0, 1.0);
  if (isSrgbChannel(channel, encoding)) c = c <= 0.0031308 ? c * 12.92 : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
  return uint8_t(std::floor(std::clamp(c, 0.0, 1.0) * 255.0 + 0.5));
}

MipChain buildMipReference(const TexelData& image, TexelEncoding encoding, MipSource source) {
  const uint32_t ch = image.channels;
  if (ch < 1 || ch > 4) throw Error("mip reference: channel count " + std::to_string(ch) + " is not 1..4");
  if (image.width == 0 || image.height == 0) throw Error("mip reference: empty image");
  if (image.texels.size() != size_t(image.width) * image.height * ch)
    throw Error("mip reference: " + std::to_string(image.texels.size()) + " bytes for a " + std::to_string(image.width) + "x" +
                std::to_string(image.height) + "x" + std::to_string(ch) + " image");

  MipChain chain{ch, encoding, {}};
  MipLevel base{image.width, image.height, std::vector<double>(image.texels.size())};
  for (size_t i = 0; i < image.texels.size(); ++i) base.texels[i] = decodeTexel(image.texels[i], uint32_t(i % ch), encoding);
  chain.levels.push_back(std::move(base));

  const uint32_t count = mipLevelCount(image.width, image.height);
  for (uint32_t k = 1; k < count; ++k) {
    const MipLevel& from = source == MipSource::Level0 ? chain.levels[0] : chain.levels[k - 1];
    MipLevel next = boxFilter(from, ch, mipLevelSize(image.width, k), mipLevelSize(image.height, k));
    chain.levels.push_back(std::move(next));
  }
  return chain;
}

std::vector<uint8_t> quantizeMipLevel(const MipChain& chain, uint32_t level) {
  if (level >= chain.levels.size())
    throw Error("mip reference: level " + std::to_string(level) + " of a " + std::to_string(chain.levels.size()) +
                "-level chain");
  const std::vector<double>& t = chain.levels[level].texels;
  std::vector<uint8_t> out(t.size());
  for (size_t i = 0; i < t.size(); ++i) out[i] = encodeTexel(t[i], uint32_t(i % chain.channels), chain.encoding);
  return out;
}

}  // namespace rtr
