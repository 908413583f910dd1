#version 460
// One mip level per dispatch (MipMode::ComputePerLevel): one thread per destination texel, reading
// the 8-bit source level written by the previous dispatch.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "mips_shared.h"
#include "render/color8.glsl"
#include "render/mip_filter.glsl"

layout(local_size_x = MIP_LEVEL_GROUP, local_size_y = MIP_LEVEL_GROUP) in;

layout(set = 0, binding = 0) uniform texture2D srcLevel;  // UNORM view of the source level
layout(set = 0, binding = 1) writeonly uniform image2D dstLevel;
layout(push_constant) uniform Push { MipPush pc; };

void main() {
  const bool srgb = pc.srgb != 0;
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
      row += tx.w[a] * decode8(texelFetch(srcLevel, ivec2(tx.first + a, ty.first + b), 0), srgb);
    sum += ty.w[b] * row;
  }
  imageStore(dstLevel, p, encode8(sum, srgb));
}
