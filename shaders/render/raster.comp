#version 460
// Compute rasteriser (docs/raster.md): one workgroup per cluster, a thread per triangle (with kRowQueue, a
// thread per row of the small triangles' boxes, below). Vertices are snapped to 1/256 pixel; integer edge functions with the top-left rule decide which pixel centres a
// triangle covers, so a shared edge is covered exactly once; each covered pixel gets one 64-bit atomicMin
// of (depth, id), alpha-masked ones after the mask's test (raster_tri.glsl). Triangles with a bounding box
// over kSharedArea pixels are set up once in a record and go to the tile list (one entry per RASTER_TILE²
// tile, raster_large.comp); those
// touching w <= 0 or leaving the guard band go to the clipping pass's list (raster_clip.comp) or, with
// pc.clip off or that list full, to the hardware hand-off list (raster_hw.vert/frag).
#extension GL_GOOGLE_include_directive : require
// With culling (pc.fromList), workgroup k takes the k-th entry this phase added to the culling pass's
// visible list (cull.comp; dispatched indirectly from its counts); without, the k-th of clusterList.
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

// kRowQueue (RTR_RASTER_ROW_QUEUE=1, render/raster.cpp; off by default until the GPU machine has timed it):
// the small triangles' box rows shared out over the workgroup. A thread looping over its own box keeps its
// warp as long as the warp's largest box, while most of its lanes' boxes are done (or empty); with the
// queue a warp's step is the widest of 32 rows. Entries: the triangle's thread << 16 | the row in its box;
// rows past the queue's end are drawn by their triangle's thread. The same atomics in another order: the
// same ids. Off: every thread draws its own box's rows.
layout(constant_id = 3) const bool kRowQueue = false;
const uint kQueueSize = 1024u;
shared uint rowCount;
shared uint rows[kQueueSize];
shared Tri smallTris[RASTER_GROUP];

void main() {
  const uint k = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (k >= (pc.fromList != 0u ? cullCounts.listed : pc.clusterCount)) return;  // the whole workgroup
  const uint clusterIndex = (pc.fromList != 0u ? cullCounts.listBase : 0u) + k;  // in clusterList
  const uint local = gl_LocalInvocationID.x;
  if (kRowQueue && local == 0u) rowCount = 0u;
  Tri t;
  const uint kind = local < clusters[clusterList[clusterIndex].y].triangleCount ? setup(clusterIndex, local, t) : kSkip;
  const uint ref = (clusterIndex << RASTER_LOCAL_BITS) | local;
  const uint height = kind == kSmall && kMeasure != RASTER_MEASURE_SETUP ? uint(t.box.w - t.box.y + 1) : 0u;
  uint own = 0u;  // the first row this thread draws itself
  if (kRowQueue) {
    barrier();  // rowCount is 0
    if (height > 0u) {
      smallTris[local] = t;
      const uint first = atomicAdd(rowCount, height);
      for (uint r = 0u; r < height && first + r < kQueueSize; ++r) rows[first + r] = (local << 16) | r;
      own = first < kQueueSize ? kQueueSize - first : 0u;
    }
    barrier();  // the queue and the triangles are written
    for (uint i = local; i < min(rowCount, kQueueSize); i += RASTER_GROUP) {
      const Tri q = smallTris[rows[i] >> 16];
      rasterRow(q, q.box.y + int(rows[i] & 0xFFFFu));
    }
  }
  for (uint r = own; r < height; ++r) rasterRow(t, t.box.y + int(r));
  if (kind == kSmall) {
    if (kMeasure == RASTER_MEASURE_SETUP && t.id == ~0u) vis[t.box.x] = packVis(t.z.x, t.id);  // keeps the setup, writes nothing
  } else if (kind == kLarge) {
    appendLarge(t, ref);
  } else if (kind == kHardware) {
    if (pc.clip != 0u) appendClip(ref);  // raster_clip.comp
    else handOff(ref);
  }
}
