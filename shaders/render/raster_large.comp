#version 460
// Compute rasteriser, large triangles (raster.comp's tile list): persistent workgroups take RASTER_TILE²
// tiles of one triangle each, a few pixels a thread.
#extension GL_GOOGLE_include_directive : require
#include "raster_tri.glsl"

layout(local_size_x = RASTER_GROUP) in;

shared Tri shared_t;
shared ivec2 shared_origin;  // the tile's first pixel; x = -1: the tile holds nothing of the triangle

void main() {
  const uint count = min(largeCount, RASTER_LARGE_CAPACITY);
  for (uint e = largeFirst + gl_WorkGroupID.x; e < count; e += gl_NumWorkGroups.x) {
    const uvec2 entry = largeTiles[e];  // uniform in the group
    if (entry.x == ~0u) continue;
    // One thread sets the triangle up for the group.
    barrier();  // the previous tile's readers are done
    if (gl_LocalInvocationID.x == 0u) {
      Tri s;
      setup(entry.x >> RASTER_LOCAL_BITS, entry.x & ((1u << RASTER_LOCAL_BITS) - 1u), s);
      const int tilesX = (s.box.z - s.box.x + RASTER_TILE) / RASTER_TILE;
      const int tile = int(entry.y);
      const ivec2 origin = s.box.xy + RASTER_TILE * ivec2(tile % tilesX, tile / tilesX);
      shared_t = s;
      shared_origin = tileTouches(s, origin) ? origin : ivec2(-1);
    }
    barrier();
    const ivec2 origin = shared_origin;
    if (origin.x < 0) continue;  // uniform in the group
    const Tri t = shared_t;
    for (uint k = gl_LocalInvocationID.x; k < RASTER_TILE * RASTER_TILE; k += RASTER_GROUP) {
      const ivec2 px = origin + ivec2(k % RASTER_TILE, k / RASTER_TILE);
      if (all(lessThanEqual(px, t.box.zw))) rasterPixel(t, px);
    }
  }
}
