#version 460
// Multi-level mip generation: each workgroup owns ONE texel of the last level this dispatch writes
// and computes, level by level in shared memory, every texel of the intermediate levels that this
// texel's box covers (up to 64x64 source texels -> 6 levels). Each texel is also written to the image
// by exactly one workgroup: the one whose last-level texel contains the texel's top-left corner.
// Intermediate levels stay in float (no 8-bit rounding) until the next dispatch re-reads the last one.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "mips_shared.h"
#include "render/color8.glsl"
#include "render/mip_filter.glsl"

layout(local_size_x = MIP_GROUP_SIZE) in;

layout(set = 0, binding = 0) uniform texture2D srcLevel;  // UNORM view of the source level
layout(set = 0, binding = 1) writeonly uniform image2D dstLevels[MIP_MAX_LEVELS_PER_DISPATCH];
layout(push_constant) uniform Push { MipPush pc; };

shared vec4 tileOdd[MIP_CAP_ODD * MIP_CAP_ODD];     // outputs 1, 3, 5 of this dispatch
shared vec4 tileEven[MIP_CAP_EVEN * MIP_CAP_EVEN];  // outputs 2, 4

// Constant indices only: dynamic indexing of storage image arrays is an optional feature.
void storeLevel(int j, ivec2 p, vec4 v) {
  switch (j) {
    case 1: imageStore(dstLevels[0], p, v); break;
    case 2: imageStore(dstLevels[1], p, v); break;
    case 3: imageStore(dstLevels[2], p, v); break;
    case 4: imageStore(dstLevels[3], p, v); break;
    case 5: imageStore(dstLevels[4], p, v); break;
    case 6: imageStore(dstLevels[5], p, v); break;
  }
}

void main() {
  const int L = pc.levels;
  const bool srgb = pc.srgb != 0;
  ivec2 size[MIP_MAX_LEVELS_PER_DISPATCH + 1];
  ivec2 lo[MIP_MAX_LEVELS_PER_DISPATCH + 1], hi[MIP_MAX_LEVELS_PER_DISPATCH + 1];
  size[0] = ivec2(pc.srcWidth, pc.srcHeight);
  for (int j = 1; j <= L; ++j) size[j] = mipNext(size[j - 1]);
  // Texels of each level under this workgroup's last-level texel: [lo, hi), level L down to 1.
  const ivec2 owner = ivec2(gl_WorkGroupID.xy);
  lo[L] = owner;
  hi[L] = owner + 1;
  for (int j = L - 1; j >= 1; --j) {
    lo[j] = (lo[j + 1] * size[j]) / size[j + 1];
    hi[j] = (hi[j + 1] * size[j] + size[j + 1] - 1) / size[j + 1];
  }

  for (int j = 1; j <= L; ++j) {
    const ivec2 ext = hi[j] - lo[j];
    const ivec2 srcLo = lo[j - 1];
    const int srcStride = hi[j - 1].x - lo[j - 1].x;
    for (int t = int(gl_LocalInvocationIndex); t < ext.x * ext.y; t += MIP_GROUP_SIZE) {
      const ivec2 p = lo[j] + ivec2(t % ext.x, t / ext.x);
      const MipTaps tx = mipTaps(p.x, size[j - 1].x, size[j].x);
      const MipTaps ty = mipTaps(p.y, size[j - 1].y, size[j].y);
      vec4 sum = vec4(0.0);
      for (int b = 0; b < ty.count; ++b) {
        vec4 row = vec4(0.0);
        for (int a = 0; a < tx.count; ++a) {
          const ivec2 q = ivec2(tx.first + a, ty.first + b);
          vec4 v;
          if (j == 1) v = decode8(texelFetch(srcLevel, q, 0), srgb);
          else {
            const int i = (q.y - srcLo.y) * srcStride + (q.x - srcLo.x);
            v = (j % 2 == 0) ? tileOdd[i] : tileEven[i];
          }
          row += tx.w[a] * v;
        }
        sum += ty.w[b] * row;
      }
      if (j < L) {
        const int i = (p.y - lo[j].y) * ext.x + (p.x - lo[j].x);
        if (j % 2 == 1) tileOdd[i] = sum; else tileEven[i] = sum;
      }
      if ((p * size[L]) / size[j] == owner) storeLevel(j, p, encode8(sum, srgb));
    }
    barrier();  // level j complete in shared memory before level j + 1 reads it
  }
}
