#version 460
// Compute rasteriser (docs/raster.md): one workgroup per cluster, a thread per triangle. Vertices are
// snapped to 1/256 pixel; integer edge functions with the top-left rule decide which pixel centres a
// triangle covers, so a shared edge is covered exactly once; each covered pixel gets one 64-bit atomicMin
// of (depth, id), alpha-masked ones after the mask's test (raster_tri.glsl). Triangles with a bounding box
// over kSharedArea pixels are set up once in a record and go to the tile list (one entry per RASTER_TILE²
// tile, raster_large.comp), those over kMediumFrom to the medium list (below); those
// touching w <= 0 or leaving the guard band go to the clipping pass's list (raster_clip.comp) or, with
// pc.clip off or that list full, to the hardware hand-off list (raster_hw.vert/frag).
#extension GL_GOOGLE_include_directive : require
// With culling (pc.fromList), workgroup k takes the k-th entry this phase added to the culling pass's
// visible list (cull.comp; dispatched indirectly from its counts); without, the k-th of clusterList.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
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

// Medium triangles (raster.h): a lane looping over its own box keeps its subgroup as long as the subgroup's
// largest box while the other lanes are done, so a box over kMediumFrom pixels is set up in a record for
// raster_large.comp, which spreads its pixels over RASTER_MEDIUM_NARROW_LANES threads (a box of up to
// kMediumNarrow pixels) or RASTER_MEDIUM_LANES; the same atomics in another order: the same ids. One 64-bit
// atomic a subgroup reserves both kinds (LargeList's mediumFound); where the list's records would not all
// hold the subgroup's, it notes where (mediumStored) and its lanes draw theirs. Nothing else here waits or
// shares memory (a queue in shared memory cost every workgroup occupancy: docs/raster.md).
// RTR_RASTER_MEDIUM and RTR_RASTER_MEDIUM_LANES (render/raster.cpp) set them for measuring; kMediumFrom of
// kSharedArea or more: no list; kMediumNarrow 0: every record of RASTER_MEDIUM_LANES.
layout(constant_id = 3) const uint kMediumFrom = RASTER_MEDIUM_FROM;
layout(constant_id = 4) const uint kMediumNarrow = RASTER_MEDIUM_NARROW_AREA;

void main() {
  const uint k = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (k >= (pc.fromList != 0u ? cullCounts.listed : pc.clusterCount)) return;  // the whole workgroup
  const uint clusterIndex = (pc.fromList != 0u ? cullCounts.listBase : 0u) + k;  // in clusterList
  const uint local = gl_LocalInvocationID.x;
  Tri t;
  const uint kind = local < clusters[clusterList[clusterIndex].y].triangleCount ? setup(clusterIndex, local, t) : kSkip;
  const uint ref = (clusterIndex << RASTER_LOCAL_BITS) | local;
  ivec2 extent = kind == kSmall && kMeasure != RASTER_MEASURE_SETUP ? t.box.zw - t.box.xy + 1 : ivec2(0);
  if (kMediumFrom < kSharedArea) {  // a specialization constant: RTR_RASTER_MEDIUM=0 leaves this out
    const uint area = uint(extent.x * extent.y);
    const bool medium = area > kMediumFrom, narrow = medium && area <= kMediumNarrow;
    const uvec4 mediumBallot = subgroupBallot(medium);
    if (subgroupBallotBitCount(mediumBallot) > 0u) {  // the same for the whole subgroup
      const uvec4 narrowBallot = subgroupBallot(narrow), wideBallot = mediumBallot & ~narrowBallot;
      const uint narrows = subgroupBallotBitCount(narrowBallot), wides = subgroupBallotBitCount(wideBallot);
      uvec2 first = uvec2(0u);  // the counts before this subgroup's
      if (subgroupElect()) {
        const uint64_t before = atomicAdd(mediumFound, (uint64_t(wides) << 32) | uint64_t(narrows));
        first = unpackUint2x32(before);
        if (first.x + narrows + first.y + wides > pc.mediumCapacity) atomicMin(mediumStored, before);
      }
      first = subgroupBroadcastFirst(first);
      const uint slot = narrow ? first.x + subgroupBallotExclusiveBitCount(narrowBallot)
                               : pc.mediumCapacity - 1u - first.y - subgroupBallotExclusiveBitCount(wideBallot);
      if (medium && first.x + narrows + first.y + wides <= pc.mediumCapacity) {
        storeLarge(RASTER_LARGE_TRIANGLES + slot, t);
        extent = ivec2(0);
      }
    }
  }
  for (int y = 0; y < extent.y; ++y)
    for (int x = 0; x < extent.x; ++x) rasterPixel(t, t.box.xy + ivec2(x, y));
  if (kind == kSmall) {
    if (kMeasure == RASTER_MEASURE_SETUP && t.id == ~0u) vis[t.box.x] = packVis(t.z.x, t.id);  // keeps the setup, writes nothing
  } else if (kind == kLarge) {
    appendLarge(t, ref);
  } else if (kind == kHardware) {
    if (pc.clip != 0u) appendClip(ref);  // raster_clip.comp
    else handOff(ref);
  }
}
