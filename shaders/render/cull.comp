#version 460
// Cluster culling, second step: one workgroup per chunk of clusters that cull_instances.comp kept, a
// thread per cluster; the level-of-detail cut, frustum, back-face cone, then
// occlusion against the depth pyramid (shaders/shared/cull.h has the tests and the phases). Visible clusters are appended to a compact list whose
// length is the size of an indirect dispatch (one workgroup per visible cluster; cull.h); culled ones are counted by
// reason. The caller zeroes the counts (x = 0, y = z = 1) before the pass.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "cull.h"

layout(local_size_x = CULL_GROUP_SIZE) in;

layout(set = 0, binding = 0, std430) readonly buffer Clusters { GpuCluster clusters[]; };
layout(set = 0, binding = 1, std430) buffer Counts { CullCounts counts; };
layout(set = 0, binding = 2, std430) writeonly buffer Visible { uint visible[]; };
layout(set = 0, binding = 3) uniform texture2D pyramid;  // R32F, farthest depth per texel (hiz.comp)
layout(set = 0, binding = 4, std430) buffer History { uint history[]; };  // 1: visible in the last LATE pass
layout(set = 0, binding = 5, std430) readonly buffer Lods { GpuClusterLod lods[]; };  // read with CULL_LOD
layout(set = 0, binding = 7, std430) readonly buffer Chunks { uvec2 chunks[]; };      // first cluster, count

layout(push_constant) uniform Push { CullPush pc; };

bool occluded(vec4 sphere) {
  const ProjectedBox b = projectBox(sphere, pc.viewProj, pc.width, pc.height);
  if (b.inFront == 0u) return false;
  const int level = pyramidLevel(b.pixels, int(pc.pyramidLevels));
  // Level sizes as DepthPyramid makes them (Vulkan mip sizes of half the image).
  const ivec4 t = pyramidTexels(b.pixels, level, max(ivec2(1), ivec2(int(pc.width), int(pc.height)) >> (level + 1)));
  float farthest = 0.0f;
  for (int y = t.y; y <= t.w; ++y)
    for (int x = t.x; x <= t.z; ++x) farthest = max(farthest, texelFetch(pyramid, ivec2(x, y), level).r);
  return b.nearestDepth > farthest;
}

void main() {
  const uint k = gl_WorkGroupID.y * max(pc.maxGroupsX, 1u) + gl_WorkGroupID.x;
  if (k >= counts.chunks) return;
  const uvec2 chunk = chunks[k];
  if (gl_LocalInvocationID.x >= chunk.y) return;
  const uint i = chunk.x + gl_LocalInvocationID.x;
  const bool wasVisible = pc.phase != CULL_SINGLE && history[i] != 0u;
  if (pc.phase == CULL_EARLY && !wasVisible) return;
  const GpuCluster c = clusters[i];
  uint reason = CULL_VISIBLE;
  if ((pc.flags & CULL_LOD) != 0u && !lodSelected(lods[i].sphere, lods[i].error.x, lods[i].parentSphere,
                                                  lods[i].error.y, pc.eye.xyz, pc.pixelsPerUnit, pc.zNear,
                                                  pc.lodThreshold))
    reason = CULL_BY_LOD;
  else if ((pc.flags & CULL_FRUSTUM) != 0u && frustumCulls(c.sphere, pc.viewProj)) reason = CULL_BY_FRUSTUM;
  else if ((pc.flags & CULL_CONE) != 0u && coneCulls(c.sphere, c.cone, pc.eye.xyz)) reason = CULL_BY_CONE;
  else if ((pc.flags & CULL_OCCLUSION) != 0u && pc.phase != CULL_EARLY && occluded(c.sphere)) reason = CULL_BY_OCCLUSION;
  if (pc.phase == CULL_LATE) history[i] = reason == CULL_VISIBLE ? 1u : 0u;
  if (reason != CULL_VISIBLE) atomicAdd(counts.culled[reason - 1u], 1u);
  else if (!(pc.phase == CULL_LATE && wasVisible)) {
    const uint n = atomicAdd(counts.listed, 1u), maxX = max(pc.maxGroupsX, 1u);
    visible[n] = i;
    atomicAdd(counts.triangles, c.triangleCount);
    if (n < maxX) atomicMax(counts.dispatch[0], n + 1u);
    if (n % maxX == 0u) atomicMax(counts.dispatch[1], n / maxX + 1u);
  }
}
