#include "trace/textures.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>

#include <glm/common.hpp>

#include "core/error.hpp"
#include "core/mip_reference.hpp"
#include "core/parallel.hpp"
#include "scene/textures.hpp"

namespace rtr::trace {
namespace {

// Byte -> linear value, the decoding of mip_reference.hpp (which the GPU's formats follow) as a table.
using Table = std::array<float, 256>;
Table decodeTable(TexelEncoding e) {
  Table t;
  for (uint32_t b = 0; b < 256; ++b) t[b] = float(decodeTexel(uint8_t(b), 0, e));
  return t;
}
const Table kUnorm = decodeTable(TexelEncoding::Unorm);
const Table kSrgb = decodeTable(TexelEncoding::Srgb);

// REPEAT for texel index i in [-1, n]: the neighbours of a bilinear footprint.
uint32_t wrap(int i, uint32_t n) { return i < 0 ? n - 1 : uint32_t(i) >= n ? 0u : uint32_t(i); }

// The texel coordinate (x - 0.5 in texel units, the footprint's first texel) and the two texels of a
// bilinear footprint along one axis, by the sampler's wrap mode. REPEAT wraps uv into [0, 1] first.
struct Axis {
  float f;  // texel coordinate
  uint32_t i0, i1;
};
Axis address(float u, uint32_t n, Wrap w) {
  if (w == Wrap::Repeat) {
    const float x = (u - std::floor(u)) * float(n) - 0.5f;
    const int i = int(std::floor(x));
    return {x, wrap(i, n), wrap(i + 1, n)};
  }
  const float x = std::clamp(u, -1e6f, 1e6f) * float(n) - 0.5f;
  const int i = int(std::floor(x));
  auto at = [&](int k) -> uint32_t {
    if (w == Wrap::ClampToEdge) return uint32_t(std::clamp(k, 0, int(n) - 1));
    const int p = 2 * int(n);
    int m = k % p;
    if (m < 0) m += p;
    return uint32_t(m < int(n) ? m : p - 1 - m);  // mirrored
  };
  return {x, at(i), at(i + 1)};
}

}  // namespace

MipTexture::MipTexture(const TexelData& image, bool srgb, const SamplerDesc& sampler)
    : channels_(image.channels), srgb_(srgb), sampler_(sampler) {
  if (channels_ != 1 && channels_ != 4)
    throw Error("texture: " + std::to_string(channels_) + " channels; the tracer samples 1 or 4");
  const MipChain chain = buildMipReference(image, srgb ? TexelEncoding::Srgb : TexelEncoding::Unorm, MipSource::PreviousLevel);
  for (uint32_t k = 0; k < chain.levels.size(); ++k) {
    const MipLevel& l = chain.levels[k];
    levels_.push_back({l.width, l.height, k == 0 ? image.texels : quantizeMipLevel(chain, k)});
  }
  halfLog2Area_ = 0.5f * std::log2(float(width()) * float(height()));
}

MipTexture::MipTexture(const BakedTexels& chain, bool srgb, const SamplerDesc& sampler)
    : channels_(bakedChannels(chain.format)), srgb_(srgb), sampler_(sampler) {
  if (bakedBlocks(chain.format)) throw Error("texture: a block-compressed chain; the tracer takes lossless ones");
  std::vector<uint8_t> bytes(chain.bytes());
  for (size_t k = 0; k < chain.pieces.size(); ++k) unpackBakedPiece(chain, k, bytes.data());
  const std::vector<uint64_t> at = chain.levelOffsets();
  for (uint32_t l = 0; l < chain.levels(); ++l) {
    const uint32_t w = mipLevelSize(chain.width, l), h = mipLevelSize(chain.height, l);
    const auto* p = bytes.data() + at[l];
    levels_.push_back({w, h, std::vector<uint8_t>(p, p + size_t(w) * h * channels_)});
  }
  halfLog2Area_ = 0.5f * std::log2(float(width()) * float(height()));
}

std::vector<uint8_t> MipTexture::chainBytes() const {
  BakedTexels layout;
  layout.format = channels_ == 1 ? BakedFormat::R8 : BakedFormat::Rgba8;
  layout.width = width();
  layout.height = height();
  const std::vector<uint64_t> at = layout.levelOffsets();
  std::vector<uint8_t> out(at.back());
  for (size_t l = 0; l < levels_.size(); ++l) std::copy(levels_[l].texels.begin(), levels_[l].texels.end(), out.begin() + at[l]);
  return out;
}

glm::vec4 MipTexture::bilinear(const Level& l, glm::vec2 uv) const {
  // Texel centres sit at half-integers.
  const Axis ax_ = address(uv.x, l.width, sampler_.wrapU), ay_ = address(uv.y, l.height, sampler_.wrapV);
  const float x = ax_.f, y = ay_.f;
  const float fx = std::floor(x), fy = std::floor(y);
  const uint32_t x0 = ax_.i0, x1 = ax_.i1, y0 = ay_.i0, y1 = ay_.i1;
  const Table& colour = srgb_ ? kSrgb : kUnorm;
  auto texel = [&](uint32_t tx, uint32_t ty) {
    const uint8_t* p = &l.texels[(size_t(ty) * l.width + tx) * channels_];
    if (channels_ == 1) return glm::vec4(kUnorm[p[0]], 0.0f, 0.0f, 1.0f);
    return glm::vec4(colour[p[0]], colour[p[1]], colour[p[2]], kUnorm[p[3]]);  // alpha is never sRGB
  };
  const float ax = x - fx, ay = y - fy;
  return glm::mix(glm::mix(texel(x0, y0), texel(x1, y0), ax), glm::mix(texel(x0, y1), texel(x1, y1), ax), ay);
}

glm::vec4 MipTexture::sample(glm::vec2 uv, float lod) const {
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) uv = glm::vec2(0.0f);
  lod = lod > 0.0f ? std::min(lod, float(levels_.size() - 1)) : 0.0f;  // NaN reads level 0
  const uint32_t l0 = uint32_t(lod);
  const float f = lod - float(l0);
  const glm::vec4 a = bilinear(levels_[l0], uv);
  return f > 0.0f ? glm::mix(a, bilinear(levels_[l0 + 1], uv), f) : a;
}

float MipTexture::lod(float uvWidth) const { return std::log2(uvWidth) + halfLog2Area_; }

SurfaceInputs materialFactors(const Material& m) { return {m.baseColor, m.roughness, m.metalness, m.emissive, 1.0f}; }

// The texture cache's variant of the tracer's chains: MipTexture's filter (float64 reference, each level
// from the one before, rounded to 8 bits); bump the number when it changes.
constexpr char kCacheVariant[] = "trace reference previous-level 1";

SceneTextures::SceneTextures(const Scene& scene, TextureCache* cache) : index_(scene.textures.size(), kNoTexture) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<uint32_t> used = sampledTextures(scene);
  std::vector<std::optional<MipTexture>> built(used.size());
  std::vector<TextureCacheKey> keys(used.size());
  std::vector<uint8_t> keyed(used.size(), 0);
  std::vector<uint32_t> decode;  // scene texture indices
  std::vector<size_t> decodeAt;  // their places in `used`
  if (cache) {
    parallelFor(used.size(), 0, [&](size_t i) {
      const Texture& t = scene.textures[used[i]];
      if (t.baked || !cache->key(scene, t, kCacheVariant, keys[i])) return;
      keyed[i] = 1;
      if (auto chain = cache->find(keys[i], t)) built[i].emplace(*chain, decodeSrgb(t), t.sampler);
    });
  }
  for (size_t i = 0; i < used.size(); ++i)
    if (!built[i]) decode.push_back(used[i]), decodeAt.push_back(i);
  cacheHits_ = uint32_t(used.size() - decode.size());
  std::vector<uint8_t> fellBack;
  decodeTextures(
      scene, decode,
      [&](size_t j, TexelData&& t) {
        const size_t i = decodeAt[j];
        try {
          built[i].emplace(t, decodeSrgb(scene.textures[used[i]]), scene.textures[used[i]].sampler);
        } catch (const Error& e) { throw Error(scene.textures[used[i]].path.string() + ": " + e.what()); }
        if (keyed[i] && !fellBack[j]) {
          const MipTexture& m = *built[i];
          cache->store(keys[i], packBakedTexels(m.channels() == 1 ? BakedFormat::R8 : BakedFormat::Rgba8, m.width(), m.height(),
                                                m.chainBytes(), 1));
        }
      },
      {}, &fellBack);
  if (cache && !decode.empty()) cache->trim();
  for (size_t i = 0; i < used.size(); ++i) {
    index_[used[i]] = uint32_t(i);
    textures_.push_back(std::move(*built[i]));
  }
  seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

const MipTexture* SceneTextures::texture(const Material& m, TextureSlot slot) const {
  const uint32_t t = m.texture(slot);
  return t < index_.size() && index_[t] != kNoTexture ? &textures_[index_[t]] : nullptr;
}

glm::vec2 slotUv(const Material& m, TextureSlot slot, const SurfaceUv& uv, float* footprintScale) {
  const UvTransform& x = m.uv[uint32_t(slot)];
  const glm::vec2 in = x.texCoord == 1 ? uv.uv1 : uv.uv0;
  if (footprintScale) *footprintScale = 1.0f;
  if (x.identity()) return in;
  if (footprintScale) *footprintScale = std::sqrt(std::abs(x.scale.x * x.scale.y));
  const glm::vec2 p = x.scale * in;
  const float c = std::cos(x.rotation), s = std::sin(x.rotation);
  return x.offset + glm::vec2(c * p.x + s * p.y, -s * p.x + c * p.y);
}

glm::vec4 SceneTextures::sample(const Material& m, TextureSlot slot, const SurfaceUv& uv, float uvWidth, glm::vec4 none) const {
  const MipTexture* t = texture(m, slot);
  if (!t) return none;
  float k;
  const glm::vec2 st = slotUv(m, slot, uv, &k);
  return t->sample(st, t->lod(uvWidth * k));
}

SurfaceInputs SceneTextures::fetch(const Material& m, const SurfaceUv& uv, float uvWidth) const {
  auto sample = [&](TextureSlot slot) { return this->sample(m, slot, uv, uvWidth, glm::vec4(1.0f)); };
  SurfaceInputs s = materialFactors(m);
  s.baseColor *= glm::vec3(sample(TextureSlot::BaseColor));
  s.roughness *= sample(TextureSlot::Roughness).r;
  s.metalness *= sample(TextureSlot::Metalness).r;
  s.alpha = alpha(m, uv, uvWidth);
  s.emissive *= glm::vec3(sample(TextureSlot::Emissive));
  return s;
}

float SceneTextures::alpha(const Material& m, const SurfaceUv& uv, float uvWidth) const {
  const MipTexture* t = texture(m, TextureSlot::AlphaMask);
  if (!t) return 1.0f;
  const glm::vec4 a = sample(m, TextureSlot::AlphaMask, uv, uvWidth, glm::vec4(1.0f));
  return t->channels() == 1 ? a.r : a.a;
}

}  // namespace rtr::trace
