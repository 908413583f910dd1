#version 460
// Compute rasteriser (docs/raster.md): one workgroup per cluster, a thread per triangle (in a subgroup with
// a large enough box, a thread per row of the small triangles' boxes, below). Vertices are snapped to 1/256 pixel; integer edge functions with the top-left rule decide which pixel centres a
// triangle covers, so a shared edge is covered exactly once; each covered pixel gets one 64-bit atomicMin
// of (depth, id), alpha-masked ones after the mask's test (raster_tri.glsl). Triangles with a bounding box
// over kSharedArea pixels are set up once in a record and go to the tile list (one entry per RASTER_TILE²
// tile, raster_large.comp); those
// touching w <= 0 or leaving the guard band go to the clipping pass's list (raster_clip.comp) or, with
// pc.clip off or that list full, to the hardware hand-off list (raster_hw.vert/frag).
#extension GL_GOOGLE_include_directive : require
// With culling (pc.fromList), workgroup k takes the k-th entry this phase added to the culling pass's
// visible list (cull.comp; dispatched indirectly from its counts); without, the k-th of clusterList.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "raster_tri.glsl"
#include "cull.h"

layout(local_size_x = RASTER_GROUP) in;

layout(set = 0, binding = 12, std430) readonly buffer Counts { CullCounts cullCounts; };

// The clipping pass's list, a workgroup per RASTER_CLIP_GROUP entries (its indirect dispatch); full: the hardware.
void appendClip(uint ref) {
  const uint n = atomicAdd(clipCount, 1u);
  if (n >= RASTER_CLIP_CAPACITY) {
    handOff(ref);
    return;
  }
  clipTriangles[n] = ref;
  if (n % RASTER_CLIP_GROUP == 0u) atomicAdd(clipGroupsX, 1u);
}

// The small triangles' pixels. A lane looping over its own box keeps its warp as long as the warp's largest
// box while most lanes are done or idle: where a subgroup's largest small box is over kRowQueueFrom pixels,
// the subgroup shares its boxes' rows out (a row a lane, so a step costs the widest of the subgroup's
// rows), in its own slice of a shared queue: offsets from a subgroup prefix sum, no shared atomic and no
// workgroup barrier. Boxes of a few pixels are cheaper drawn by their own lane, unstepped (docs/raster.md,
// "What bounds each pass": the threshold's counts). Entries: the triangle's lane << 16 | the row in its box;
// rows past the slice their own lane draws. The same atomics in another order: the same ids.
// Off by default (measured on the H200: the pixel-sized triangles of large scenes lose 2x with it, chosen
// per subgroup too); RTR_RASTER_ROW_QUEUE=0/1/auto (render/raster.cpp) chooses for measuring.
layout(constant_id = 3) const uint kRowQueueFrom = 0xFFFFFFFFu;
const uint kQueueSize = 1024u;
shared uint rows[kQueueSize];
shared Tri smallTris[RASTER_GROUP];

void main() {
  const uint k = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (k >= (pc.fromList != 0u ? cullCounts.listed : pc.clusterCount)) return;  // the whole workgroup
  const uint clusterIndex = (pc.fromList != 0u ? cullCounts.listBase : 0u) + k;  // in clusterList
  const uint local = gl_LocalInvocationID.x;
  Tri t;
  const uint kind = local < clusters[clusterList[clusterIndex].y].triangleCount ? setup(clusterIndex, local, t) : kSkip;
  const uint ref = (clusterIndex << RASTER_LOCAL_BITS) | local;
  const uvec2 extent = kind == kSmall && kMeasure != RASTER_MEASURE_SETUP ? uvec2(t.box.zw - t.box.xy + 1) : uvec2(0u);
  if (subgroupMax(extent.x * extent.y) > kRowQueueFrom) {  // the same for the whole subgroup
    const uint slice = kQueueSize / gl_NumSubgroups, base = gl_SubgroupID * slice;
    const uint first = subgroupExclusiveAdd(extent.y), queued = min(subgroupAdd(extent.y), slice);
    if (extent.y > 0u) smallTris[local] = t;
    for (uint r = 0u; r < extent.y && first + r < slice; ++r) rows[base + first + r] = (local << 16) | r;
    subgroupBarrier();  // an execution and (shared) memory barrier for the subgroup: its entries are written
    for (uint i = gl_SubgroupInvocationID; i < queued; i += gl_SubgroupSize) {
      const uint e = rows[base + i];
      const Tri q = smallTris[e >> 16];
      rasterRow(q, q.box.y + int(e & 0xFFFFu));
    }
    for (uint r = first < slice ? slice - first : 0u; r < extent.y; ++r) rasterRow(t, t.box.y + int(r));
  } else {
    for (int y = 0; y < int(extent.y); ++y)
      for (int x = 0; x < int(extent.x); ++x) rasterPixel(t, t.box.xy + ivec2(x, y));
  }
  if (kind == kSmall) {
    if (kMeasure == RASTER_MEASURE_SETUP && t.id == ~0u) vis[t.box.x] = packVis(t.z.x, t.id);  // keeps the setup, writes nothing
  } else if (kind == kLarge) {
    appendLarge(t, ref);
  } else if (kind == kHardware) {
    if (pc.clip != 0u) appendClip(ref);  // raster_clip.comp
    else handOff(ref);
  }
}
