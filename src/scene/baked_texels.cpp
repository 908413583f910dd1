#include "scene/baked_texels.hpp"

#include <zstd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>

#include "core/error.hpp"
#include "core/mip_reference.hpp"
#include "core/parallel.hpp"
#include "scene/bc.hpp"

namespace rtr {

bool bakedKnown(uint32_t f) { return f >= uint32_t(BakedFormat::Rgba8) && f <= uint32_t(BakedFormat::Bc4); }
uint32_t bakedChannels(BakedFormat f) { return f == BakedFormat::R8 || f == BakedFormat::Bc4 ? 1 : 4; }
bool bakedBlocks(BakedFormat f) { return f == BakedFormat::Bc1 || f == BakedFormat::Bc3 || f == BakedFormat::Bc4; }

uint64_t bakedLevelBytes(BakedFormat f, uint32_t w, uint32_t h) {
  if (!bakedBlocks(f)) return uint64_t(w) * h * bakedChannels(f);
  return uint64_t((w + 3) / 4) * ((h + 3) / 4) * (f == BakedFormat::Bc3 ? 16 : 8);
}

namespace {

// Each block of a level with the offsets of its 16 texels; where the level is not a multiple of 4, the
// offsets repeat its last column and row, and `inside` (bit i for texel i) marks the real ones.
template <class Fn>
void forBlocks(uint32_t w, uint32_t h, uint32_t channels, unsigned threads, Fn&& fn) {
  constexpr uint32_t kRows = 16;  // rows of blocks per piece
  const uint32_t bw = (w + 3) / 4, bh = (h + 3) / 4;
  parallelFor((bh + kRows - 1) / kRows, threads, [&](size_t piece) {
    for (uint32_t by = uint32_t(piece) * kRows; by < std::min(bh, uint32_t(piece + 1) * kRows); ++by)
      for (uint32_t bx = 0; bx < bw; ++bx) {
        size_t at[16];
        uint32_t inside = 0;
        for (uint32_t i = 0; i < 16; ++i) {
          const uint32_t x = bx * 4 + i % 4, y = by * 4 + i / 4;
          at[i] = (size_t(std::min(y, h - 1)) * w + std::min(x, w - 1)) * channels;
          inside |= uint32_t(x < w && y < h) << i;
        }
        fn(size_t(by) * bw + bx, at, inside);
      }
  });
}

}  // namespace

std::vector<uint8_t> decodeBakedLevel(BakedFormat f, uint32_t w, uint32_t h, const uint8_t* data) {
  const uint32_t ch = bakedChannels(f);
  const size_t n = size_t(w) * h * ch;
  if (!bakedBlocks(f)) return std::vector<uint8_t>(data, data + n);
  std::vector<uint8_t> out(n);
  const size_t blockBytes = f == BakedFormat::Bc3 ? 16 : 8;
  forBlocks(w, h, ch, 1, [&](size_t b, const size_t at[16], uint32_t inside) {
    uint8_t t[64];
    const uint8_t* block = data + b * blockBytes;
    if (f == BakedFormat::Bc4) bc::decodeChannel(block, t, 1);
    if (f == BakedFormat::Bc1) bc::decodeColour(block, true, t);
    if (f == BakedFormat::Bc3) bc::decodeChannel(block, t + 3, 4), bc::decodeColour(block + 8, false, t);
    if (f == BakedFormat::Bc1)
      for (int i = 0; i < 16; ++i) t[4 * i + 3] = 255;
    for (int i = 0; i < 16; ++i)
      if (inside >> i & 1) std::memcpy(&out[at[i]], t + i * ch, ch);
  });
  return out;
}

std::vector<uint8_t> encodeBakedLevel(BakedFormat f, uint32_t w, uint32_t h, const uint8_t* texels, unsigned threads) {
  const uint32_t ch = bakedChannels(f);
  if (!bakedBlocks(f)) return std::vector<uint8_t>(texels, texels + size_t(w) * h * ch);
  std::vector<uint8_t> out(bakedLevelBytes(f, w, h));
  const size_t blockBytes = f == BakedFormat::Bc3 ? 16 : 8;
  forBlocks(w, h, ch, threads, [&](size_t b, const size_t at[16], uint32_t) {
    uint8_t t[64], alpha[16];
    for (int i = 0; i < 16; ++i) std::memcpy(t + i * ch, texels + at[i], ch);
    uint8_t* block = out.data() + b * blockBytes;
    if (f == BakedFormat::Bc4) return bc::encodeChannel(t, block);
    if (f == BakedFormat::Bc1) return bc::encodeColour(t, block);
    for (int i = 0; i < 16; ++i) alpha[i] = t[4 * i + 3];
    bc::encodeChannel(alpha, block);
    bc::encodeColour(t, block + 8);
  });
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
    // Blocks are stored as they are: zstd halves them but unpacks them at about 0.4 GB/s a core, which
    // cost lavapipe's 200-texture start a quarter of its CPU (docs/bench/textures.md).
    if (bakedBlocks(format)) return out.assign(src, src + n);
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
