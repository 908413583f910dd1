#version 460
// Compute rasteriser, large triangles (raster.comp's tile list): persistent workgroups take RASTER_TILE²
// tiles of one triangle each, a few pixels a thread. Every thread reads the triangle's record (set up once
// by raster.comp, the same address for the whole group): no shared memory, no barrier, no fetch chain.
#extension GL_GOOGLE_include_directive : require
#include "raster_tri.glsl"

layout(local_size_x = RASTER_GROUP) in;

void main() {
  const uint count = min(largeCount, RASTER_LARGE_CAPACITY);
  for (uint e = largeFirst + gl_WorkGroupID.x; e < count; e += gl_NumWorkGroups.x) {
    const uvec2 entry = largeTiles[e];  // uniform in the group
    if (entry.x == ~0u) continue;
    const Tri t = loadLarge(entry.x);
    const int tilesX = (t.box.z - t.box.x + RASTER_TILE) / RASTER_TILE;
    const ivec2 origin = t.box.xy + RASTER_TILE * ivec2(int(entry.y) % tilesX, int(entry.y) / tilesX);
    if (!tileTouches(t, origin)) continue;  // uniform in the group
    for (uint k = gl_LocalInvocationID.x; k < RASTER_TILE * RASTER_TILE; k += RASTER_GROUP) {
      const ivec2 px = origin + ivec2(k % RASTER_TILE, k / RASTER_TILE);
      if (all(lessThanEqual(px, t.box.zw))) rasterPixel(t, px);
    }
  }
}
