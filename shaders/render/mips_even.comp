#version 460
// Mip levels that halve exactly (each axis even, or already 1, which copies): every weight is 1/2, so no
// tap loops and no divisions. Each workgroup reduces a 64x64 tile of the source level to up to 6
// levels. Thread t reads a 4x4 block and keeps its four level-1 texels and one level-2 texel in
// registers; threads are numbered in Morton order, so a level-(2+k) texel's children are consecutive
// entries of the level-2 tile in shared memory (levels 3..6: two more barriers).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
#include "mips_shared.h"
#include "render/color8.glsl"
#include "render/mip_filter.glsl"

layout(local_size_x = MIP_GROUP_SIZE) in;

shared vec4 tile2[256];  // the tile's 16x16 level-2 texels, Morton order
shared vec4 tile4[16];   // its 4x4 level-4 texels, Morton order

// Morton index -> x (even bits) of a tile of up to 16x16; y is morton(m >> 1).
int morton(int m) {
  m &= 0x55;
  m = (m | (m >> 1)) & 0x33;
  return (m | (m >> 2)) & 0x0F;
}
ivec2 mortonXY(int m) { return ivec2(morton(m), morton(m >> 1)); }

// The 2x2 box of texel p from its children a (0,0), b (1,0), c (0,1), d (1,1) in a level of size n.
// A child past the edge exists only where that axis has size 1 (this level copies it): reuse its
// neighbour, which gives the plain copy.
vec4 box(vec4 a, vec4 b, vec4 c, vec4 d, ivec2 p, ivec2 n) {
  if (2 * p.x + 1 >= n.x) { b = a; d = c; }
  if (2 * p.y + 1 >= n.y) { c = a; d = b; }
  return 0.25 * ((a + b) + (c + d));
}

void put(int j, ivec2 p, ivec2 size, vec4 v) {
  if (j > pc.levels || any(greaterThanEqual(p, size))) return;
  storeLevel(j, p, v);
  if (j == pc.levels) storeLastLevel(p, size, v);
}

void main() {
  ivec2 size[MIP_MAX_LEVELS_PER_DISPATCH + 1];
  size[0] = ivec2(pc.srcWidth, pc.srcHeight);
  [[unroll]] for (int j = 1; j <= MIP_MAX_LEVELS_PER_DISPATCH; ++j) size[j] = mipNext(size[j - 1]);
  const int t = int(gl_LocalInvocationIndex);
  const ivec2 group = ivec2(gl_WorkGroupID.xy);

  // Levels 1 and 2 from this thread's 4x4 source block (clamped reads: an axis of size 1 repeats its
  // texel; reads past the right/bottom edge only feed texels that are not stored).
  const ivec2 p2 = group * (MIP_EVEN_TILE / 4) + mortonXY(t);
  vec4 l1[4];
  [[unroll]] for (int k = 0; k < 4; ++k) {
    const ivec2 p1 = 2 * p2 + ivec2(k & 1, k >> 1);
    const ivec2 q = 2 * p1;
    const ivec2 last = size[0] - 1;
    l1[k] = box(loadSource(min(q, last)), loadSource(min(q + ivec2(1, 0), last)),
                loadSource(min(q + ivec2(0, 1), last)), loadSource(min(q + ivec2(1, 1), last)), p1, size[0]);
    put(1, p1, size[1], l1[k]);
  }
  const vec4 l2 = box(l1[0], l1[1], l1[2], l1[3], p2, size[1]);
  put(2, p2, size[2], l2);
  if (pc.levels <= 2) return;

  // Levels 3 and 4: thread t < 16 owns level-4 texel t and its four level-3 children (level-2 entries
  // 16t .. 16t + 15).
  tile2[t] = l2;
  barrier();
  if (t < 16) {
    const ivec2 p4 = group * (MIP_EVEN_TILE / 16) + mortonXY(t);
    vec4 l3[4];
    [[unroll]] for (int k = 0; k < 4; ++k) {
      const int m = 4 * t + k;
      const ivec2 p3 = group * (MIP_EVEN_TILE / 8) + mortonXY(m);
      l3[k] = box(tile2[4 * m], tile2[4 * m + 1], tile2[4 * m + 2], tile2[4 * m + 3], p3, size[2]);
      put(3, p3, size[3], l3[k]);
    }
    const vec4 l4 = box(l3[0], l3[1], l3[2], l3[3], p4, size[3]);
    put(4, p4, size[4], l4);
    tile4[t] = l4;
  }
  if (pc.levels <= 4) return;

  // Levels 5 and 6: one thread (4 + 1 texels).
  barrier();
  if (t == 0) {
    vec4 l5[4];
    [[unroll]] for (int k = 0; k < 4; ++k) {
      const ivec2 p5 = group * (MIP_EVEN_TILE / 32) + ivec2(k & 1, k >> 1);
      l5[k] = box(tile4[4 * k], tile4[4 * k + 1], tile4[4 * k + 2], tile4[4 * k + 3], p5, size[4]);
      put(5, p5, size[5], l5[k]);
    }
    put(6, group, size[6], box(l5[0], l5[1], l5[2], l5[3], group, size[5]));
  }
}
