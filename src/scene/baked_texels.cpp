#include "scene/baked_texels.hpp"

#include <zstd.h>

#include <algorithm>
#include <cstring>

#include "core/error.hpp"
#include "core/mip_reference.hpp"
#include "core/parallel.hpp"

namespace rtr {

uint32_t bakedTexelBytes(BakedFormat f) { return f == BakedFormat::R8 ? 1 : 4; }

uint32_t BakedTexels::levels() const { return mipLevelCount(width, height); }

std::vector<uint64_t> BakedTexels::levelOffsets() const {
  std::vector<uint64_t> at{0};
  for (uint32_t l = 0; l < levels(); ++l) {
    const uint64_t n = uint64_t(mipLevelSize(width, l)) * mipLevelSize(height, l) * bakedTexelBytes(format);
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
  if (chain.size() != bytes) throw Error("baked texels: " + std::to_string(chain.size()) + " bytes for a chain of " + std::to_string(bytes));
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
  const uint32_t ch = bakedTexelBytes(t.format);
  const size_t n = size_t(t.width) * t.height * ch;
  // The pieces that cover level 0, unpacked into a buffer of whole pieces, then cut to the level.
  const size_t pieces = (n + kBakedPiece - 1) / kBakedPiece;
  std::vector<uint8_t> chain(std::min<uint64_t>(t.bytes(), pieces * kBakedPiece));
  for (size_t k = 0; k < pieces; ++k) unpackBakedPiece(t, k, chain.data());
  chain.resize(n);
  return {t.width, t.height, ch, std::move(chain)};
}

}  // namespace rtr
