#pragma once
// Block compression of 4x4 texel blocks, ours (docs/rtrscene-format.md, "Block-compressed texels"): BC1
// colour by the block's principal axis refined by least squares, BC4 (and BC3's alpha) by its extremes
// refined the same way, and the decoders the baker measures their error with. A block's bytes depend on
// its 16 texels alone, so an image encodes to the same bytes in any order, on any number of threads.
#include <cstdint>

namespace rtr::bc {

// 16 texels, RGBA8 row by row (alpha ignored), to one 8-byte BC1 block in four-colour mode (the block
// reads the same as BC1 and as BC3's colour half).
void encodeColour(const uint8_t rgba[64], uint8_t block[8]);
// 16 one-channel texels to one 8-byte BC4 block (also BC3's alpha half).
void encodeChannel(const uint8_t texels[16], uint8_t block[8]);

// `bc1`: the block is BC1's (c0 <= c1 selects three colours and black); else BC3's colour half (always four
// colours). Writes RGB of 16 texels at stride 4 bytes; alpha untouched.
void decodeColour(const uint8_t block[8], bool bc1, uint8_t rgba[64]);
// Writes 16 texels at `stride` bytes apart.
void decodeChannel(const uint8_t block[8], uint8_t* texels, int stride);

}  // namespace rtr::bc
