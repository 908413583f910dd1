#version 460
// One level of the depth pyramid: each texel the farthest (largest) of the 2 × 2 source texels it covers,
// clamped at the source's edge (level sizes halve rounding up, so an odd edge texel covers its one or two
// sources). The source is the depth image itself (a D32 view or an R32F image, depth in .r) for level 0,
// the previous level otherwise.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "cull.h"

layout(local_size_x = HIZ_GROUP_SIZE, local_size_y = HIZ_GROUP_SIZE) in;

layout(set = 0, binding = 0) uniform texture2D src;
layout(set = 0, binding = 1, r32f) uniform writeonly image2D dst;

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, imageSize(dst)))) return;
  const ivec2 last = textureSize(src, 0) - 1;
  const ivec2 s = 2 * p;
  const float d = max(max(texelFetch(src, min(s, last), 0).r, texelFetch(src, min(s + ivec2(1, 0), last), 0).r),
                      max(texelFetch(src, min(s + ivec2(0, 1), last), 0).r, texelFetch(src, min(s + 1, last), 0).r));
  imageStore(dst, p, vec4(d));
}
