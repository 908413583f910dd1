#version 460
// One mip level per dispatch (MipMode::ComputePerLevel): one thread per destination texel. Besides the
// 8-bit level it writes a float copy that the next dispatch reads, so rounding errors do not pile up
// level after level (8-bit sources drift 2 LSB from the reference after a few odd 1D reductions).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "mips_shared.h"
#include "render/color8.glsl"
#include "render/mip_filter.glsl"

layout(local_size_x = MIP_LEVEL_GROUP, local_size_y = MIP_LEVEL_GROUP) in;

layout(set = 0, binding = 0) uniform texture2D srcLevel;  // UNORM view of the source level
layout(set = 0, binding = 1) writeonly uniform image2D dstLevel;
layout(set = 0, binding = 2, std430) readonly buffer ScratchIn { vec4 srcTexels[]; };    // row-major
layout(set = 0, binding = 3, std430) writeonly buffer ScratchOut { vec4 dstTexels[]; };
layout(push_constant) uniform Push { MipPush pc; };

void main() {
  const bool srgb = pc.srgb != 0;
  initSrgbDecodeLut();  // before any thread returns
  const ivec2 srcSize = ivec2(pc.srcWidth, pc.srcHeight);
  const ivec2 dstSize = mipNext(srcSize);
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, dstSize))) return;
  const MipTaps tx = mipTaps(p.x, srcSize.x, dstSize.x);
  const MipTaps ty = mipTaps(p.y, srcSize.y, dstSize.y);
  vec4 sum = vec4(0.0);
  for (int b = 0; b < ty.count; ++b) {
    vec4 row = vec4(0.0);
    for (int a = 0; a < tx.count; ++a)
    {
      const ivec2 q = ivec2(tx.first + a, ty.first + b);
      row += tx.w[a] * (pc.fromScratch != 0 ? srcTexels[q.y * srcSize.x + q.x] : decodeLut(texelFetch(srcLevel, q, 0), srgb));
    }
    sum += ty.w[b] * row;
  }
  imageStore(dstLevel, p, encode8(sum, srgb));
  dstTexels[p.y * dstSize.x + p.x] = sum;
}
