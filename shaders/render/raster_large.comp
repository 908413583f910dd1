#version 460
// Compute rasteriser, large triangles (raster.comp's tile list): persistent workgroups take RASTER_TILE²
// tiles of one triangle each, a few pixels a thread, and the medium triangles, a few pixels a lane. Every
// thread reads the triangle's record (set up once by raster.comp, the same address for the whole group or
// for a medium triangle's 16 or 32 threads): no shared memory, no barrier, no fetch chain.
#extension GL_GOOGLE_include_directive : require
#include "raster_tri.glsl"

layout(local_size_x = RASTER_GROUP) in;

// The medium records [first, end) of one kind (LargeList), `lanes` threads each over its box's pixels (at
// most kSharedArea: a few each); `back`: the kind recorded from the list's end.
void drawMedium(uint first, uint end, uint lanes, bool back) {
  const uint slots = RASTER_GROUP / lanes, lane = gl_LocalInvocationID.x % lanes;
  for (uint e = first + gl_WorkGroupID.x * slots + gl_LocalInvocationID.x / lanes; e < end; e += gl_NumWorkGroups.x * slots) {
    const Tri t = loadLarge(RASTER_LARGE_TRIANGLES + (back ? pc.mediumCapacity - 1u - e : e));
    const int w = t.box.z - t.box.x + 1, n = w * (t.box.w - t.box.y + 1);
    for (int k = int(lane); k < n; k += int(lanes)) rasterPixel(t, t.box.xy + ivec2(k % w, k / w));
  }
}

void main() {
  // Medium triangles (raster.comp's records after the large ones'): those of up to RASTER_MEDIUM_NARROW_AREA
  // pixels two a subgroup, then the larger ones.
  const uvec2 first = unpackUint2x32(mediumFirst), end = min(unpackUint2x32(mediumFound), unpackUint2x32(mediumStored));
  drawMedium(first.x, end.x, RASTER_MEDIUM_NARROW_LANES, false);
  drawMedium(first.y, end.y, RASTER_MEDIUM_LANES, true);
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
