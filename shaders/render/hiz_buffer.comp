#version 460
// The depth pyramid's level 0 straight from the compute rasteriser's 64-bit visibility buffer (depth bits in
// each pixel's high word; raster.h): as hiz.comp, without an intermediate depth image. An empty pixel
// (all ones, a NaN as float) counts as the far plane.
#extension GL_GOOGLE_include_directive : require
#include "cull.h"

layout(local_size_x = HIZ_GROUP_SIZE, local_size_y = HIZ_GROUP_SIZE) in;

layout(set = 0, binding = 0, std430) readonly buffer Vis { uint vis[]; };  // two words a pixel, low first
layout(set = 0, binding = 1, r32f) uniform writeonly image2D dst;
layout(push_constant) uniform Push { uvec2 size; };  // the visibility buffer's, in pixels

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, imageSize(dst)))) return;
  const ivec2 last = ivec2(size) - 1;
  const ivec2 lo = min(2 * p, last);
  const ivec2 hi = mix(min(2 * p + 1, last), last, equal(p, imageSize(dst) - 1));
  float d = 0.0f;
  for (int y = lo.y; y <= hi.y; ++y)
    for (int x = lo.x; x <= hi.x; ++x) {
      const uint bits = vis[2u * (uint(y) * size.x + uint(x)) + 1u];
      d = max(d, bits == ~0u ? 1.0f : uintBitsToFloat(bits));
    }
  imageStore(dst, p, vec4(d));
}
