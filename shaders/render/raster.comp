#version 460
// Compute rasteriser (docs/raster.md): one workgroup per cluster, a thread per triangle. Vertices are
// snapped to 1/256 pixel; integer edge functions with the top-left rule decide which pixel centres a
// triangle covers, so a shared edge is covered exactly once; each covered pixel gets one 64-bit atomicMin
// of (depth, id), alpha-masked ones after the mask's test (raster_tri.glsl). Triangles with a bounding box
// over kSharedArea pixels are set up once in a record and go to the tile list (one entry per RASTER_TILE²
// tile, raster_large.comp); those
// touching w <= 0 or leaving the guard band go to the hardware hand-off list (raster_hw.vert/frag).
#extension GL_GOOGLE_include_directive : require
// With culling (pc.fromList), workgroup k takes the k-th entry this phase added to the culling pass's
// visible list (cull.comp; dispatched indirectly from its counts); without, the k-th of clusterList.
#include "raster_tri.glsl"
#include "cull.h"

layout(local_size_x = RASTER_GROUP) in;

layout(set = 0, binding = 12, std430) readonly buffer Counts { CullCounts cullCounts; };

// Past the list's capacity a triangle is counted, not stored (the draw skips those entries).
void handOff(uint ref) {
  const uint n = atomicAdd(vertexCount, 3u) / 3u;
  if (n < pc.handOffCapacity) hwTriangles[n] = ref;
}

void main() {
  const uint k = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (k >= (pc.fromList != 0u ? cullCounts.listed : pc.clusterCount)) return;
  const uint clusterIndex = (pc.fromList != 0u ? cullCounts.listBase : 0u) + k;  // in clusterList
  const uint local = gl_LocalInvocationID.x;
  Tri t;
  const uint kind = local < clusters[clusterList[clusterIndex].y].triangleCount ? setup(clusterIndex, local, t) : kSkip;
  const uint ref = (clusterIndex << RASTER_LOCAL_BITS) | local;
  if (kind == kSmall) {
    for (int y = t.box.y; y <= t.box.w; ++y)
      for (int x = t.box.x; x <= t.box.z; ++x) rasterPixel(t, ivec2(x, y));
  } else if (kind == kLarge) {
    const ivec2 tiles = (t.box.zw - t.box.xy + RASTER_TILE) / RASTER_TILE;
    const uint n = uint(tiles.x * tiles.y), first = atomicAdd(largeCount, n), record = atomicAdd(largeTriCount, 1u);
    // A full list hands the triangle to the hardware; its reserved entries that fit are marked empty.
    const bool fits = first + n <= RASTER_LARGE_CAPACITY && record < RASTER_LARGE_TRIANGLES;
    if (fits) storeLarge(record, t);
    for (uint i = 0u; i < n && first + i < RASTER_LARGE_CAPACITY; ++i) largeTiles[first + i] = uvec2(fits ? record : ~0u, i);
    if (!fits) handOff(ref);
  } else if (kind == kHardware) {
    handOff(ref);
  }
}
