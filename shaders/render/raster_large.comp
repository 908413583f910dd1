#version 460
// Compute rasteriser, large triangles (raster.comp's tile list): persistent workgroups take RASTER_TILE²
// tiles of one triangle each, a few pixels a thread, and the medium triangles, a few pixels a lane. Every
// thread reads the triangle's record (set up once by raster.comp, the same address for the whole group or
// RASTER_MEDIUM_LANES threads): no shared memory, no barrier, no fetch chain.
#extension GL_GOOGLE_include_directive : require
#include "raster_tri.glsl"

layout(local_size_x = RASTER_GROUP) in;

void main() {
  // Medium triangles (raster.comp's records after the large ones'): RASTER_MEDIUM_LANES threads each, over
  // its box's pixels (at most kSharedArea: a few each).
  const uint slots = RASTER_GROUP / RASTER_MEDIUM_LANES, lane = gl_LocalInvocationID.x % RASTER_MEDIUM_LANES;
  const uint mediumEnd = min(mediumCount, RASTER_MEDIUM_TRIANGLES);
  for (uint e = mediumFirst + gl_WorkGroupID.x * slots + gl_LocalInvocationID.x / RASTER_MEDIUM_LANES; e < mediumEnd;
       e += gl_NumWorkGroups.x * slots) {
    const Tri t = loadLarge(RASTER_LARGE_TRIANGLES + e);
    const int w = t.box.z - t.box.x + 1, n = w * (t.box.w - t.box.y + 1);
    for (int k = int(lane); k < n; k += int(RASTER_MEDIUM_LANES)) rasterPixel(t, t.box.xy + ivec2(k % w, k / w));
  }
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
