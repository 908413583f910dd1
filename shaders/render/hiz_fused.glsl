// The fused depth pyramid (included by hiz_fused.comp and hiz_fused_buffer.comp, which define
// `float loadSource(ivec2 p)`, the source's depth at texel p): up to HIZ_FUSED_LEVELS levels in one
// dispatch, by the reduction rule of hiz.comp (each texel the farthest of the 2 × 2 below it, the last of a
// row or column also the odd last one below it; shaders/shared/cull.h).
//
// A workgroup owns a tile of the source: HIZ_TILE × HIZ_TILE texels from a multiple of HIZ_TILE, the last
// tile of a row or column up to the source's end (HIZ_TILE to 2 HIZ_TILE − 1 texels; a source narrower
// than HIZ_TILE is one tile). As the origin o is a multiple of 2^(j+1), the tile's level j has texels
// (o >> (j+1)) + q for q < max(1, n >> (j+1)) (n: the tile's texels), its last texel is the level's last
// only in the last tile, and there it takes the odd last texels exactly as the whole level does. So each
// workgroup reduces its tile level by level in shared memory with no texel from another tile, and the
// result equals hiz.comp's, texel for texel.
#extension GL_GOOGLE_include_directive : require
#include "cull.h"

layout(local_size_x = HIZ_FUSED_SIDE * HIZ_FUSED_SIDE) in;

layout(set = 0, binding = 1, r32f) uniform writeonly image2D dst0;  // the dispatch's levels, first to last
layout(set = 0, binding = 2, r32f) uniform writeonly image2D dst1;  // (those past pc.levels: not written)
layout(set = 0, binding = 3, r32f) uniform writeonly image2D dst2;
layout(set = 0, binding = 4, r32f) uniform writeonly image2D dst3;
layout(set = 0, binding = 5, r32f) uniform writeonly image2D dst4;
#if HIZ_FUSED_LEVELS > 5
layout(set = 0, binding = 6, r32f) uniform writeonly image2D dst5;
#endif
layout(push_constant) uniform Push { HizPush pc; };

// Levels 0, 2, 4 of the tile (up to HIZ_TILE - 1 texels a side in a last tile), and 1, 3, 5 (up to
// HIZ_TILE / 2 - 1).
shared float tileEven[(HIZ_TILE - 1) * (HIZ_TILE - 1)];
shared float tileOdd[(HIZ_TILE / 2 - 1) * (HIZ_TILE / 2 - 1)];

float loadSource(ivec2 p);

void store(int j, ivec2 p, float d) {
  switch (j) {
    case 0: imageStore(dst0, p, vec4(d)); break;
    case 1: imageStore(dst1, p, vec4(d)); break;
    case 2: imageStore(dst2, p, vec4(d)); break;
    case 3: imageStore(dst3, p, vec4(d)); break;
    case 4: imageStore(dst4, p, vec4(d)); break;
#if HIZ_FUSED_LEVELS > 5
    default: imageStore(dst5, p, vec4(d)); break;
#endif
  }
}

// Level j - 1's texel q (j > 0: in shared memory, row length w) or the source's (j = 0: tile origin o).
float below(int j, ivec2 o, ivec2 q, int w) {
  return j == 0 ? loadSource(o + q) : (j % 2 == 1) ? tileEven[q.y * w + q.x] : tileOdd[q.y * w + q.x];
}

// The farthest of the texels [lo, hi] below (j uniform: each branch is taken by the whole workgroup).
float farthest(int j, ivec2 o, ivec2 lo, ivec2 hi, int w) {
  float d = 0.0f;
  if (j == 0) {
    for (int y = lo.y; y <= hi.y; ++y)
      for (int x = lo.x; x <= hi.x; ++x) d = max(d, loadSource(o + ivec2(x, y)));
  } else {
    for (int y = lo.y; y <= hi.y; ++y)
      for (int x = lo.x; x <= hi.x; ++x) d = max(d, below(j, o, ivec2(x, y), w));
  }
  return d;
}

// Level j's texel q of the tile: to shared memory (row length w) when a level follows, and to the image.
void put(int j, int levels, ivec2 o, ivec2 q, int w, float d) {
  if (j + 1 < levels) {
    if (j % 2 == 0) tileEven[q.y * w + q.x] = d;
    else tileOdd[q.y * w + q.x] = d;
  }
  store(j, (o >> (j + 1)) + q, d);
}

void main() {
  const ivec2 size = ivec2(pc.width, pc.height);
  const ivec2 tiles = max(ivec2(1), size / HIZ_TILE);
  const ivec2 tile = ivec2(gl_WorkGroupID.xy);
  const ivec2 o = tile * HIZ_TILE;
  ivec2 n = mix(ivec2(HIZ_TILE), size - o, equal(tile, tiles - 1));  // the tile's source texels
  const int levels = int(pc.levels);
  // HIZ_FUSED_SIDE² threads, each taking the texels t + HIZ_FUSED_SIDE k of a level (rows of neighbours:
  // coalesced reads).
  const ivec2 t = ivec2(gl_LocalInvocationIndex % HIZ_FUSED_SIDE, gl_LocalInvocationIndex / HIZ_FUSED_SIDE);
  for (int j = 0; j < levels; ++j) {
    const ivec2 m = max(ivec2(1), n / 2);                // the tile's texels of level j
    const ivec2 f = mix(m, m - 1, equal(n & 1, ivec2(1)));  // those whose sources are exactly 2q and 2q + 1
    if (j > 0) barrier();                                // level j - 1 is in shared memory
    for (int qy = t.y; qy < f.y; qy += HIZ_FUSED_SIDE)
      for (int qx = t.x; qx < f.x; qx += HIZ_FUSED_SIDE) {
        const ivec2 s = 2 * ivec2(qx, qy);
        float d;
        if (j == 0)
          d = max(max(loadSource(o + s), loadSource(o + s + ivec2(1, 0))), max(loadSource(o + s + ivec2(0, 1)), loadSource(o + s + 1)));
        else
          d = max(max(below(j, o, s, n.x), below(j, o, s + ivec2(1, 0), n.x)),
                  max(below(j, o, s + ivec2(0, 1), n.x), below(j, o, s + 1, n.x)));
        put(j, levels, o, ivec2(qx, qy), m.x, d);
      }
    // Where n is odd, the last column and row: their last texel's sources run to the tile's end (for a
    // 1-wide level below, its only texel).
    const int column = f.x < m.x ? m.y : 0, row = f.y < m.y ? f.x : 0;
    for (int i = int(gl_LocalInvocationIndex); i < column + row; i += HIZ_FUSED_SIDE * HIZ_FUSED_SIDE) {
      const ivec2 q = i < column ? ivec2(m.x - 1, i) : ivec2(i - column, m.y - 1);
      put(j, levels, o, q, m.x, farthest(j, o, 2 * q, mix(2 * q + 1, n - 1, equal(q, m - 1)), n.x));
    }
    n = m;
  }
}
