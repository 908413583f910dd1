#version 460
// One level of the depth pyramid: each texel the farthest (largest) of the 2 × 2 source texels below it;
// the last texel of a row or column also takes the source's odd last one (sizes halve rounding down;
// shaders/shared/cull.h). The source is the depth image itself (a D32 view or an R32F image, depth in .r)
// for level 0, the previous level otherwise.
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
  const ivec2 lo = min(2 * p, last);
  const ivec2 hi = mix(min(2 * p + 1, last), last, equal(p, imageSize(dst) - 1));
  float d = 0.0f;
  for (int y = lo.y; y <= hi.y; ++y)
    for (int x = lo.x; x <= hi.x; ++x) d = max(d, texelFetch(src, ivec2(x, y), 0).r);
  imageStore(dst, p, vec4(d));
}
