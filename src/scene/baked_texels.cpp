#include "scene/baked_texels.hpp"

#include <squish.h>
#include <zstd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>

#include "core/error.hpp"
#include "core/mip_reference.hpp"
#include "core/parallel.hpp"

namespace rtr {

bool bakedKnown(uint32_t f) { return f >= uint32_t(BakedFormat::Rgba8) && f <= uint32_t(BakedFormat::Bc4); }
uint32_t bakedChannels(BakedFormat f) { return f == BakedFormat::R8 || f == BakedFormat::Bc4 ? 1 : 4; }
bool bakedBlocks(BakedFormat f) { return f == BakedFormat::Bc1 || f == BakedFormat::Bc3 || f == BakedFormat::Bc4; }

uint64_t bakedLevelBytes(BakedFormat f, uint32_t w, uint32_t h) {
  if (!bakedBlocks(f)) return uint64_t(w) * h * bakedChannels(f);
  return uint64_t((w + 3) / 4) * ((h + 3) / 4) * (f == BakedFormat::Bc3 ? 16 : 8);
}

namespace {

int squishFlags(BakedFormat f) { return f == BakedFormat::Bc1 ? squish::kDxt1 : squish::kDxt5; }

// BC4 is ours: bookworm's libsquish 1.15 encodes and decodes its kBc4 as BC1 colour. A block: red_0, red_1,
// then a 3-bit index per texel (row-major, little-endian from bit 0). red_0 > red_1: eight values from
// red_0 to red_1 in sevenths; else six in fifths, then 0 and 255 (Vulkan's data format specification).
void bc4Palette(const uint8_t* block, int v[8]) {
  const int r0 = block[0], r1 = block[1];
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

// Endpoints the block's extremes (eight-value mode), each texel the nearest value: the error is at most
// (max − min) / 14 plus rounding.
void bc4Encode(const uint8_t* texels, uint32_t w, uint32_t h, uint32_t bx, uint32_t by, uint8_t* block) {
  uint8_t t[16];
  int lo = 255, hi = 0;
  for (uint32_t i = 0; i < 16; ++i) {
    const uint32_t x = std::min(bx * 4 + i % 4, w - 1), y = std::min(by * 4 + i / 4, h - 1);  // edges repeat
    t[i] = texels[size_t(y) * w + x];
    lo = std::min<int>(lo, t[i]);
    hi = std::max<int>(hi, t[i]);
  }
  block[0] = uint8_t(hi);
  block[1] = uint8_t(lo);
  int v[8];
  bc4Palette(block, v);
  uint64_t bits = 0;
  for (uint32_t i = 0; i < 16; ++i) {
    int best = 0;
    for (int k = 1; k < 8; ++k)
      if (std::abs(v[k] - t[i]) < std::abs(v[best] - t[i])) best = k;
    bits |= uint64_t(best) << (3 * i);
  }
  for (int b = 0; b < 6; ++b) block[2 + b] = uint8_t(bits >> (8 * b));
}

void bc4Decode(const uint8_t* block, uint32_t w, uint32_t h, uint32_t bx, uint32_t by, uint8_t* texels) {
  int v[8];
  bc4Palette(block, v);
  uint64_t bits = 0;
  for (int b = 0; b < 6; ++b) bits |= uint64_t(block[2 + b]) << (8 * b);
  for (uint32_t i = 0; i < 16; ++i) {
    const uint32_t x = bx * 4 + i % 4, y = by * 4 + i / 4;
    if (x < w && y < h) texels[size_t(y) * w + x] = uint8_t(v[(bits >> (3 * i)) & 7]);
  }
}

}  // namespace

std::vector<uint8_t> decodeBakedLevel(BakedFormat f, uint32_t w, uint32_t h, const uint8_t* data) {
  const size_t n = size_t(w) * h;
  if (!bakedBlocks(f)) return std::vector<uint8_t>(data, data + n * bakedChannels(f));
  if (f == BakedFormat::Bc4) {
    std::vector<uint8_t> r(n);
    for (uint32_t by = 0, bw = (w + 3) / 4; by < (h + 3) / 4; ++by)
      for (uint32_t bx = 0; bx < bw; ++bx) bc4Decode(data + (size_t(by) * bw + bx) * 8, w, h, bx, by, r.data());
    return r;
  }
  std::vector<uint8_t> rgba(n * 4);
  squish::DecompressImage(rgba.data(), int(w), int(h), data, squishFlags(f));
  return rgba;
}

std::vector<uint8_t> encodeBakedLevel(BakedFormat f, uint32_t w, uint32_t h, const uint8_t* texels) {
  const size_t n = size_t(w) * h;
  if (!bakedBlocks(f)) return std::vector<uint8_t>(texels, texels + n * bakedChannels(f));
  std::vector<uint8_t> out(bakedLevelBytes(f, w, h));
  if (f == BakedFormat::Bc4) {
    for (uint32_t by = 0, bw = (w + 3) / 4; by < (h + 3) / 4; ++by)
      for (uint32_t bx = 0; bx < bw; ++bx) bc4Encode(texels, w, h, bx, by, out.data() + (size_t(by) * bw + bx) * 8);
    return out;
  }
  squish::CompressImage(texels, int(w), int(h), out.data(), squishFlags(f) | squish::kColourClusterFit);
  return out;
}

uint32_t BakedTexels::levels() const { return mipLevelCount(width, height); }

std::vector<uint64_t> BakedTexels::levelOffsets() const {
  std::vector<uint64_t> at{0};
  for (uint32_t l = 0; l < levels(); ++l) {
    const uint64_t n = bakedLevelBytes(format, mipLevelSize(width, l), mipLevelSize(height, l));
    at.push_back((at.back() + n + 15) & ~uint64_t(15));
  }
  return at;
}

size_t BakedTexels::pieceBytes(size_t k) const {
  return size_t(std::min<uint64_t>(kBakedPiece, bytes() - uint64_t(k) * kBakedPiece));
}

std::shared_ptr<const BakedTexels> packBakedTexels(BakedFormat format, uint32_t width, uint32_t height,
                                                   std::vector<uint8_t> chain, unsigned threads) {
  auto t = std::make_shared<BakedTexels>();
  t->format = format;
  t->width = width;
  t->height = height;
  const uint64_t bytes = t->bytes();
  if (chain.size() != bytes)
    throw Error("baked texels: " + std::to_string(chain.size()) + " bytes for a chain of " + std::to_string(bytes));
  const size_t count = size_t((bytes + kBakedPiece - 1) / kBakedPiece);
  std::vector<std::vector<uint8_t>> packed(count);
  parallelFor(count, threads, [&](size_t k) {
    const size_t n = t->pieceBytes(k);
    const uint8_t* src = chain.data() + k * kBakedPiece;
    std::vector<uint8_t>& out = packed[k];
    out.resize(ZSTD_compressBound(n));
    // Each frame carries its content checksum: a damaged piece is found when it is unpacked, even where
    // the file's checksum was not checked (fuzz builds).
    thread_local std::unique_ptr<ZSTD_CCtx, size_t (*)(ZSTD_CCtx*)> ctx(ZSTD_createCCtx(), ZSTD_freeCCtx);
    ZSTD_CCtx_reset(ctx.get(), ZSTD_reset_session_and_parameters);
    ZSTD_CCtx_setParameter(ctx.get(), ZSTD_c_compressionLevel, 3);
    ZSTD_CCtx_setParameter(ctx.get(), ZSTD_c_checksumFlag, 1);
    const size_t z = ZSTD_compress2(ctx.get(), out.data(), out.size(), src, n);
    if (ZSTD_isError(z) || z >= n) out.assign(src, src + n);  // incompressible: stored as it is
    else out.resize(z);
  });
  auto owned = std::make_shared<std::vector<uint8_t>>();
  for (const std::vector<uint8_t>& p : packed) {
    t->pieces.push_back({owned->size(), uint32_t(p.size())});
    owned->insert(owned->end(), p.begin(), p.end());
  }
  t->data = *owned;
  t->owner = owned;
  return t;
}

void unpackBakedPiece(const BakedTexels& t, size_t k, uint8_t* chain) {
  const BakedPiece& p = t.pieces.at(k);
  const size_t n = t.pieceBytes(k);
  uint8_t* dst = chain + k * kBakedPiece;
  const uint8_t* src = t.data.data() + p.at;
  if (p.stored == n) {
    std::memcpy(dst, src, n);
    return;
  }
  // One context per thread: creating one per piece costs more than a small piece's unpacking.
  thread_local std::unique_ptr<ZSTD_DCtx, size_t (*)(ZSTD_DCtx*)> ctx(ZSTD_createDCtx(), ZSTD_freeDCtx);
  const size_t got = ZSTD_decompressDCtx(ctx.get(), dst, n, src, p.stored);
  if (ZSTD_isError(got) || got != n)
    throw fileError(t.file, "byte " + std::to_string(t.fileOffset + p.at),
                    "baked texture piece " + std::to_string(k) + " does not unpack to its " + std::to_string(n) + " bytes (" +
                        (ZSTD_isError(got) ? ZSTD_getErrorName(got) : std::to_string(got) + " bytes") + ")");
}

TexelData unpackBakedLevel0(const BakedTexels& t) {
  const uint32_t ch = bakedChannels(t.format);
  const size_t n = bakedLevelBytes(t.format, t.width, t.height);
  // The pieces that cover level 0, unpacked into a buffer of whole pieces, then cut to the level.
  const size_t pieces = (n + kBakedPiece - 1) / kBakedPiece;
  std::vector<uint8_t> chain(std::min<uint64_t>(t.bytes(), pieces * kBakedPiece));
  for (size_t k = 0; k < pieces; ++k) unpackBakedPiece(t, k, chain.data());
  if (bakedBlocks(t.format)) return {t.width, t.height, ch, decodeBakedLevel(t.format, t.width, t.height, chain.data())};
  chain.resize(n);
  return {t.width, t.height, ch, std::move(chain)};
}

}  // namespace rtr
