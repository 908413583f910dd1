#pragma once
// Textures stored as the GPU samples them (.rtrscene version 6, chunk TEXS; docs/rtrscene-format.md): the
// whole mip chain in the GPU's texel format, cut into pieces of kBakedPiece bytes of texels, each piece
// zstd-compressed on its own (or stored as it is where zstd does not shrink it), so that a loader
// unpacks the pieces on all cores straight into staging memory: no image decode, no mip pass. No GPU here.
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/image.hpp"

namespace rtr {

// Texel formats. Lossless: what decodeChannels() gives a slot (4: RGBA8, sRGB or not as the texture; 1: R8).
// Block-compressed (4x4 blocks): BC1 for opaque colour (its alpha reads 1), BC3 for colour with alpha, BC4
// for one channel.
enum class BakedFormat : uint32_t { Rgba8 = 1, R8 = 2, Bc1 = 3, Bc3 = 4, Bc4 = 5 };
bool bakedKnown(uint32_t format);
uint32_t bakedChannels(BakedFormat f);  // of the decoded texels: 1 or 4
bool bakedBlocks(BakedFormat f);        // block-compressed
uint64_t bakedLevelBytes(BakedFormat f, uint32_t width, uint32_t height);
// Decodes one level of `f` to 8-bit texels of bakedChannels(f) channels (BC: scene/bc.hpp's decoders).
std::vector<uint8_t> decodeBakedLevel(BakedFormat f, uint32_t width, uint32_t height, const uint8_t* data);
// Encodes one level of 8-bit texels (bakedChannels(f) channels) to `f` (BC: scene/bc.hpp's encoders), in
// pieces of block rows on `threads` (0: all cores): the same bytes on any number.
std::vector<uint8_t> encodeBakedLevel(BakedFormat f, uint32_t width, uint32_t height, const uint8_t* texels,
                                      unsigned threads = 1);

constexpr size_t kBakedPiece = size_t(1) << 18;  // bytes of texels per piece (the last one of a texture shorter)

struct BakedPiece {
  uint64_t at = 0;      // offset of its stored bytes in `BakedTexels::data`
  uint32_t stored = 0;  // bytes stored; == its texel bytes: stored as they are, else one zstd frame
};

struct BakedTexels {
  BakedFormat format = BakedFormat::Rgba8;
  uint32_t width = 0, height = 0;  // of level 0; the chain goes down to 1 x 1 (mipLevelCount)
  std::vector<BakedPiece> pieces;
  std::span<const uint8_t> data;      // the stored pieces (in the mapped file, or `owner`'s bytes)
  std::shared_ptr<const void> owner;  // keeps `data` alive
  std::string file;                   // for messages: the file, and the offset of `data` in it
  uint64_t fileOffset = 0;

  uint32_t levels() const;
  // Byte offset of each level in the unpacked chain (16-byte aligned), and the chain's size (the last entry).
  std::vector<uint64_t> levelOffsets() const;
  uint64_t bytes() const { return levelOffsets().back(); }
  size_t pieceBytes(size_t k) const;  // texel bytes of piece k
};

// Packs a chain laid out as levelOffsets() says (`chain` holds bytes() bytes): pieces compressed on all cores
// (block-compressed chains: stored as they are).
std::shared_ptr<const BakedTexels> packBakedTexels(BakedFormat format, uint32_t width, uint32_t height,
                                                   std::vector<uint8_t> chain, unsigned threads = 0);

// Unpacks piece k into `chain` (which holds bytes() bytes) at k * kBakedPiece. Throws rtr::Error naming the
// file and the byte offset of a piece that does not unpack to its size.
void unpackBakedPiece(const BakedTexels& t, size_t k, uint8_t* chain);
// Level 0 alone, as decoded texels (the CPU tracer's input; block-compressed levels decoded); pieces
// unpacked on the calling thread.
TexelData unpackBakedLevel0(const BakedTexels& t);

}  // namespace rtr
