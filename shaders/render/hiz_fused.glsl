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

layout(local_size_x = HIZ_FUSED_GROUP) in;

layout(set = 0, binding = 1, r32f) uniform writeonly image2D dst0;  // the dispatch's levels, first to last
layout(set = 0, binding = 2, r32f) uniform writeonly image2D dst1;  // (those past pc.levels: not written)
layout(set = 0, binding = 3, r32f) uniform writeonly image2D dst2;
layout(set = 0, binding = 4, r32f) uniform writeonly image2D dst3;
layout(set = 0, binding = 5, r32f) uniform writeonly image2D dst4;
layout(set = 0, binding = 6, r32f) uniform writeonly image2D dst5;
layout(push_constant) uniform Push { HizPush pc; };

// Levels 0, 2, 4 of the tile (up to 63 × 63 texels in a last tile), and 1, 3, 5 (up to 31 × 31).
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
    default: imageStore(dst5, p, vec4(d)); break;
  }
}

// Level j - 1's texel q of the tile, from shared memory (row length w).
float below(int j, ivec2 q, int w) { return (j % 2 == 1) ? tileEven[q.y * w + q.x] : tileOdd[q.y * w + q.x]; }

void main() {
  const ivec2 size = ivec2(pc.width, pc.height);
  const ivec2 tiles = max(ivec2(1), size / HIZ_TILE);
  const ivec2 tile = ivec2(gl_WorkGroupID.xy);
  const ivec2 o = tile * HIZ_TILE;
  ivec2 n = mix(ivec2(HIZ_TILE), size - o, equal(tile, tiles - 1));  // the tile's source texels
  const int levels = int(pc.levels);
  for (int j = 0; j < levels; ++j) {
    const ivec2 m = max(ivec2(1), n / 2);  // the tile's texels of level j
    if (j > 0) barrier();                  // level j - 1 is in shared memory
    for (int i = int(gl_LocalInvocationIndex); i < m.x * m.y; i += HIZ_FUSED_GROUP) {
      const ivec2 q = ivec2(i % m.x, i / m.x);
      // Sources 2q and 2q + 1; the last texel of a row or column up to the tile's end.
      const ivec2 lo = min(2 * q, n - 1);
      const ivec2 hi = mix(min(2 * q + 1, n - 1), n - 1, equal(q, m - 1));
      float d = 0.0f;
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) d = max(d, j == 0 ? loadSource(o + ivec2(x, y)) : below(j, ivec2(x, y), n.x));
      if (j + 1 < levels) {
        if (j % 2 == 0) tileEven[i] = d;
        else tileOdd[i] = d;
      }
      store(j, (o >> (j + 1)) + q, d);
    }
    n = m;
  }
}
