#pragma once
// Float64 reference for GPU mip chains: a box filter in linear light with exact fractional coverage.
//
// Level sizes are Vulkan's: max(1, W >> k) x max(1, H >> k), levels until 1 x 1.
// Coverage rule (per axis, separable): destination texel x of a level of width w covers the source
// interval [x * W / w, (x + 1) * W / w) of the source of width W, and source texel i (covering [i, i+1))
// gets the weight |[i, i+1) ∩ that interval| / (W / w). In integers: weight(i -> x) =
// |[i*w, (i+1)*w) ∩ [x*W, (x+1)*W)| / W. Weights of one destination texel sum to 1, and every source
// texel's weights over all destination texels sum to w / W, so each level's mean equals the source mean.
// For even W and w = W/2 this is the plain 2x2 average; for odd W a texel on a boundary is split.
// The 2D weight is the product of the x and y weights.
//
// Decoding: UNORM byte b -> b / 255. sRGB: channels 0..2 (R, G, B) through the exact sRGB EOTF, the
// 4th channel (alpha, of a 4-channel image only) linear, like VK_FORMAT_R8*_SRGB.
#include <cstdint>
#include <vector>

#include "core/image.hpp"

namespace rtr {

enum class TexelEncoding { Unorm, Srgb };

// Where level k >= 2 is filtered from. Level0: the ideal box over the original texels (default).
// PreviousLevel: the same rule applied to level k-1 in double (what a cascaded GPU chain computes without
// intermediate rounding). The two are identical whenever every level halves exactly (power-of-two sizes).
enum class MipSource { Level0, PreviousLevel };

struct MipLevel {
  uint32_t width = 0, height = 0;
  std::vector<double> texels;  // linear values, row-major, `channels` interleaved per texel
};

struct MipChain {
  uint32_t channels = 0;
  TexelEncoding encoding = TexelEncoding::Unorm;
  std::vector<MipLevel> levels;  // levels[0] is the decoded source
};

uint32_t mipLevelCount(uint32_t width, uint32_t height);  // floor(log2(max(w, h))) + 1; 0 for an empty image
uint32_t mipLevelSize(uint32_t size, uint32_t level);     // max(1, size >> level)

double decodeTexel(uint8_t value, uint32_t channel, TexelEncoding encoding);
// Linear -> byte: clamp to [0,1], sRGB-encode where decodeTexel decoded, round to nearest (ties up).
uint8_t encodeTexel(double linear, uint32_t channel, TexelEncoding encoding);

// Throws rtr::Error for channels outside 1..4, an empty image or a texel count that does not match.
MipChain buildMipReference(const TexelData& image, TexelEncoding encoding, MipSource source = MipSource::Level0);

// 8-bit texels of one level, laid out like TexelData::texels.
std::vector<uint8_t> quantizeMipLevel(const MipChain& chain, uint32_t level);

}  // namespace rtr
