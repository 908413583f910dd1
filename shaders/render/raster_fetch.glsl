// Triangle fetch shared by the compute rasteriser and its hardware hand-off: cluster -> instance -> draw
// -> indices -> positions (placed by the instance's transform), the same buffers the shading pass reads.
#extension GL_GOOGLE_include_directive : require
#include "frame.h"
#include "cluster.h"
#include "raster.h"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1, std430) readonly buffer Clusters { GpuCluster clusters[]; };
layout(set = 0, binding = 2, std430) readonly buffer Draws { GpuDraw draws[]; };
layout(set = 0, binding = 3, std430) readonly buffer Positions { float positions[]; };
layout(set = 0, binding = 4, std430) readonly buffer Indices32 { uint indices32[]; };
layout(set = 0, binding = 5, std430) readonly buffer Indices16 { uint indices16[]; };  // two per word
// The vertex stage may not write storage buffers (vertexPipelineStoresAndAtomics is not enabled).
#ifndef RASTER_VIS_ACCESS
#define RASTER_VIS_ACCESS
#endif
#ifndef RASTER_LIST_ACCESS
#define RASTER_LIST_ACCESS
#endif
layout(set = 0, binding = 6, std430) RASTER_VIS_ACCESS buffer Vis { uint64_t vis[]; };
// The triangles handed to the hardware, after a VkDrawIndirectCommand (3 vertices each).
layout(set = 0, binding = 7, std430) RASTER_LIST_ACCESS buffer HardwareList {
  uint vertexCount, instanceCount, firstVertex, firstInstance;
  uint hwTriangles[];
};
// Large triangles' tiles (raster.comp -> raster_large.comp): (triangle as in hwTriangles, tile index).
// raster_large.comp takes entries [largeFirst, largeCount): with culling, the second phase's only.
// The medium triangles (raster.h) found so far, two counts in one 64-bit word (one atomic a subgroup): x =
// low half, those of RASTER_MEDIUM_NARROW_LANES, recorded from the list's front (record RASTER_LARGE_TRIANGLES
// + k of largeTris), y = high half, those of RASTER_MEDIUM_LANES, from its back (RASTER_LARGE_TRIANGLES +
// pc.mediumCapacity - 1 - k). mediumStored: the counts when the first subgroup's records did not fit (all
// before it fit, none after it; all ones: none), so the records are [mediumFirst, min(mediumFound,
// mediumStored)) of each kind; mediumFirst: with culling, the first phase's mediumFound.
layout(set = 0, binding = 10, std430) RASTER_LIST_ACCESS buffer LargeList {
  uint largeCount, largeFirst, largeTriCount, largePad0;
  uint64_t mediumFound, mediumFirst, mediumStored, largePad1;
  uvec2 largeTiles[];  // (the triangle's record in largeTris, tile index)
};
// The triangles crossing the near plane or the guard band, for raster_clip.comp (raster.h); clipFirst: with
// culling, the second phase's first.
layout(set = 0, binding = 15, std430) RASTER_LIST_ACCESS buffer ClipList {
  uint clipGroupsX, clipGroupsY, clipGroupsZ;  // VkDispatchIndirectCommand: a workgroup per RASTER_CLIP_GROUP entries
  uint clipCount, clipFirst, clipPad0, clipPad1, clipPad2;
  uint clipTriangles[];
};
// The large triangles' setup, largeTriCount records, then the medium ones' (raster.h, LargeList).
layout(set = 0, binding = 14, std430) RASTER_LIST_ACCESS buffer LargeTris { RasterLargeTri largeTris[]; };
layout(set = 0, binding = 13, std430) readonly buffer Instances { GpuInstance instances[]; };
// The clusters drawn, (GpuInstance, GpuCluster record) each: the culling pass's visible list or, without
// it, every instance's full-detail clusters (GpuScene::baseEntries). Workgroups, tiles and hand-off entries
// name a cluster by its position here.
layout(set = 0, binding = 11, std430) readonly buffer ClusterList { uvec2 clusterList[]; };
layout(push_constant) uniform Push { RasterPush pc; };

// The cluster at `entry` of clusterList, its instance and mirrored flag filled in (records are the mesh's).
// Records are read member by member, only what the rasterisers use (not the bounds, not the normal
// matrix): a copy of a whole record stays one whole-struct load in the SPIR-V, whose unused parts only the
// driver may drop.
GpuCluster listedCluster(uint entry) {
  const uvec2 e = clusterList[entry];
  GpuCluster c;
  c.instance = e.x;
  c.firstTriangle = clusters[e.y].firstTriangle;
  c.triangleCount = clusters[e.y].triangleCount;
  c.flags = clusters[e.y].flags;
  if ((instances[e.x].info.y & INSTANCE_MIRRORED) != 0u) c.flags |= CLUSTER_MIRRORED;
  return c;
}

// Instance i's transform and info.
GpuInstance placedInstance(uint i) {
  GpuInstance inst;
  inst.transform = instances[i].transform;
  inst.info = instances[i].info;
  return inst;
}

vec3 position(uint i) { return vec3(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]); }

uint vertexIndex(GpuDraw d, uint i) {
  if ((d.flags & DRAW_INDEX16) == 0u) return indices32[d.firstIndex + i];
  uint k = d.firstIndex + i;
  return (indices16[k >> 1] >> ((k & 1u) * 16u)) & 0xFFFFu;  // little-endian halves
}

// Vertex indices (into the streams) of triangle `local` of cluster `c`.
uvec3 triangleVertices(GpuCluster c, GpuDraw d, uint local) {
  const uint k = 3u * (c.firstTriangle + local);
  return uvec3(vertexIndex(d, k), vertexIndex(d, k + 1u), vertexIndex(d, k + 2u)) + d.vertexOffset;
}

// Clip-space position of vertex i placed by instance `inst`, computed as the vertex stages do.
vec4 clipPosition(GpuInstance inst, uint i) { return frame.viewProj * (inst.transform * vec4(position(i), 1.0)); }

// The alpha test of vis.frag given the mask texel: whether the material cuts the pixel out.
bool maskCuts(GpuMaterial m, vec4 mask) {
  return m.baseColor.a * ((m.textures2.w & MATERIAL_MASK_RED) != 0u ? mask.r : mask.a) < m.roughMetal.z;
}

// The mask's texcoords from set 0's (its KHR_texture_transform).
vec2 maskTexcoord(GpuMaterial m, vec2 uv) {
  const vec4 r0 = m.uvTransform[2 * SLOT_MASK], r1 = m.uvTransform[2 * SLOT_MASK + 1];
  return vec2(dot(r0.xy, uv) + r0.z, dot(r1.xy, uv) + r1.z);
}

uint64_t packVis(float depth, uint id) { return (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(id); }
