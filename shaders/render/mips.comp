#version 460
// Multi-level mip generation for any sizes (odd ones included): each workgroup owns ONE texel of the
// last level this dispatch writes and computes, level by level in shared memory, every texel of the
// intermediate levels that this texel's box covers (up to 64x64 source texels -> 6 levels). Each texel
// is also written to the image by exactly one workgroup: the one whose last-level texel contains the
// texel's top-left corner. Levels that halve exactly take mips_even.comp instead (much faster).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
#include "mips_shared.h"
#include "render/color8.glsl"
#include "render/mip_filter.glsl"

layout(local_size_x = MIP_GROUP_SIZE) in;

shared vec4 tileOdd[MIP_CAP_ODD * MIP_CAP_ODD];     // outputs 1, 3, 5 of this dispatch
shared vec4 tileEven[MIP_CAP_EVEN * MIP_CAP_EVEN];  // outputs 2, 4

// A level-(j-1) texel as linear colour: level 0 of the dispatch from the image, the others from the
// tile that holds level j-1 (j is a constant once the level loop is unrolled).
vec4 loadLevel(int j, ivec2 q, ivec2 srcLo, int srcStride) {
  if (j == 1) return loadSource(q);
  const int i = (q.y - srcLo.y) * srcStride + (q.x - srcLo.x);
  return (j % 2 == 0) ? tileOdd[i] : tileEven[i];
}

// Every per-level loop below is unrolled over the MIP_MAX_LEVELS_PER_DISPATCH possible levels (L, the
// number written, only masks iterations), so the per-level arrays are indexed by constants and live in
// registers, the tile and the storage image of each level are chosen at compile time, and no thread
// spills them to local memory.
void main() {
  const int L = pc.levels;
  ivec2 size[MIP_MAX_LEVELS_PER_DISPATCH + 1];
  size[0] = ivec2(pc.srcWidth, pc.srcHeight);
  [[unroll]] for (int j = 1; j <= MIP_MAX_LEVELS_PER_DISPATCH; ++j) size[j] = mipNext(size[j - 1]);
  ivec2 sizeL = size[1];  // size of the last level written
  [[unroll]] for (int j = 2; j <= MIP_MAX_LEVELS_PER_DISPATCH; ++j)
    if (j == L) sizeL = size[j];
  // Texels of each level under this workgroup's last-level texel: [lo, hi), level L down to 1.
  const ivec2 owner = ivec2(gl_WorkGroupID.xy);
  ivec2 lo[MIP_MAX_LEVELS_PER_DISPATCH + 1], hi[MIP_MAX_LEVELS_PER_DISPATCH + 1];
  lo[0] = hi[0] = ivec2(0);  // level 0 is read from the image: no range needed
  [[unroll]] for (int j = MIP_MAX_LEVELS_PER_DISPATCH; j >= 1; --j) {
    if (j >= L || j == MIP_MAX_LEVELS_PER_DISPATCH) {
      lo[j] = owner;
      hi[j] = owner + 1;
    } else {
      lo[j] = (lo[j + 1] * size[j]) / size[j + 1];
      hi[j] = (hi[j + 1] * size[j] + size[j + 1] - 1) / size[j + 1];
    }
  }

  [[unroll]] for (int j = 1; j <= MIP_MAX_LEVELS_PER_DISPATCH; ++j) {
    if (j > L) break;
    const ivec2 ext = hi[j] - lo[j];
    const ivec2 srcLo = lo[j - 1];
    const int srcStride = hi[j - 1].x - lo[j - 1].x;
    // Texels of level j this workgroup stores: those whose top-left corner lies in its last-level
    // texel, p * n_L / n_j == owner, i.e. [ceil(owner n_j / n_L), ceil((owner + 1) n_j / n_L)).
    const ivec2 ownLo = (owner * size[j] + sizeL - 1) / sizeL;
    const ivec2 ownHi = ((owner + 1) * size[j] + sizeL - 1) / sizeL;
    // Both axes halve exactly (power-of-two levels): the 2x2 box with weights 1/2, as mipTaps gives it.
    const bool halves = all(equal(size[j - 1], 2 * size[j]));
    for (int t = int(gl_LocalInvocationIndex); t < ext.x * ext.y; t += MIP_GROUP_SIZE) {
      const int row = t / ext.x;
      const ivec2 p = lo[j] + ivec2(t - row * ext.x, row);
      vec4 sum;
      if (halves) {
        const ivec2 q = 2 * p;
        const vec4 r0 = 0.5 * loadLevel(j, q, srcLo, srcStride) + 0.5 * loadLevel(j, q + ivec2(1, 0), srcLo, srcStride);
        const vec4 r1 = 0.5 * loadLevel(j, q + ivec2(0, 1), srcLo, srcStride) + 0.5 * loadLevel(j, q + ivec2(1, 1), srcLo, srcStride);
        sum = 0.5 * r0 + 0.5 * r1;
      } else {
        const MipTaps tx = mipTaps(p.x, size[j - 1].x, size[j].x);
        const MipTaps ty = mipTaps(p.y, size[j - 1].y, size[j].y);
        sum = vec4(0.0);
        [[unroll]] for (int b = 0; b < 3; ++b) {
          if (b >= ty.count) break;
          vec4 r = vec4(0.0);
          [[unroll]] for (int a = 0; a < 3; ++a) {
            if (a >= tx.count) break;
            r += tx.w[a] * loadLevel(j, ivec2(tx.first + a, ty.first + b), srcLo, srcStride);
          }
          sum += ty.w[b] * r;
        }
      }
      if (j < L) {
        const int i = t;  // (p - lo[j]) in row-major order of the [lo, hi) range
        if (j % 2 == 1) tileOdd[i] = sum; else tileEven[i] = sum;
      }
      if (all(greaterThanEqual(p, ownLo)) && all(lessThan(p, ownHi))) {
        storeLevel(j, p, sum);
        if (j == L) storeLastLevel(p, size[j], sum);
      }
    }
    if (j < L) barrier();  // level j complete in shared memory before level j + 1 reads it
  }
}
