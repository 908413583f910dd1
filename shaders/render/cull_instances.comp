#version 460
// Culling, first step: one thread per instance (GpuCullInstance, cluster.h). An instance whose sphere lies
// outside the frustum is culled whole, one test for all its clusters. With the level-of-detail cut, only
// the levels whose clusters can be in the cut from somewhere in the instance's sphere are kept (the level
// window, docs/virtual-geometry.md): a far instance does not visit its full-detail clusters. The
// clusters kept are cut into
// chunks of up to CULL_GROUP_SIZE, one workgroup each of the cluster step (cull.comp), dispatched
// indirectly from counts.chunkDispatch (two-dimensional past maxGroupsX chunks, as the visible list).
#extension GL_GOOGLE_include_directive : require
#include "cull.h"

layout(local_size_x = CULL_GROUP_SIZE) in;

layout(set = 0, binding = 1, std430) buffer Counts { CullCounts counts; };
layout(set = 0, binding = 6, std430) readonly buffer Instances { GpuCullInstance cullInstances[]; };
layout(set = 0, binding = 7, std430) writeonly buffer Chunks { uvec4 chunks[]; };  // instance, first record, count
layout(set = 0, binding = 8, std430) readonly buffer Levels { GpuCullLevel levels[]; };

layout(push_constant) uniform Push { CullPush pc; };

void emit(uint instance, uint first, uint count) {
  const uint n = (count + CULL_GROUP_SIZE - 1u) / CULL_GROUP_SIZE;
  if (n == 0u) return;
  const uint base = atomicAdd(counts.chunks, n), maxX = max(pc.maxGroupsX, 1u), last = base + n - 1u;
  for (uint k = 0u; k < n; ++k)
    chunks[base + k] = uvec4(instance, first + k * CULL_GROUP_SIZE, min(uint(CULL_GROUP_SIZE), count - k * CULL_GROUP_SIZE), 0u);
  atomicMax(counts.chunkDispatch[0], min(last + 1u, maxX));
  atomicMax(counts.chunkDispatch[1], last / maxX + 1u);
  atomicAdd(counts.tested, count);
}

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  const GpuCullInstance c = cullInstances[i];
  // Its clusters' spheres lie in its sphere: a plane that has it wholly outside has them too.
  if ((pc.flags & CULL_FRUSTUM) != 0u && frustumCulls(c.sphere, pc.viewProj)) {
    atomicAdd(counts.instancesCulled, 1u);
    return;
  }
  const GpuCullLevel full = levels[c.levels.x];
  if ((pc.flags & CULL_LOD) == 0u) {
    emit(i, full.firstCluster, full.clusterCount);
    return;
  }
  // Every cluster's distance term of lodProjectedError (cluster_lod.h) lies in [near, far]: its spheres
  // lie in lodSphere. A level can hold a cluster of the cut only if its least error can be at most the
  // threshold (seen from `far`) and its parents' largest above it (from `near`); a little slack for rounding.
  // The levels' errors are the mesh's, scaled by the instance's largest stretch.
  const float ppu = pc.pixelsPerUnit * c.placement.x;
  const float d = length(c.lodSphere.xyz - pc.eye.xyz);
  const float near = max(d - c.lodSphere.w, pc.zNear) * 0.999f, far = max(d + c.lodSphere.w, pc.zNear) * 1.001f;
  uint lo = c.levels.y, hi = 0u;
  for (uint l = 0u; l < c.levels.y; ++l) {
    const GpuCullLevel v = levels[c.levels.x + l];
    if (v.minError * ppu / far <= pc.lodThreshold &&
        (v.maxParentError >= LOD_ERROR_INFINITE || v.maxParentError * ppu / near > pc.lodThreshold))
      lo = min(lo, l), hi = l;
  }
  if (lo > hi) {  // no level can be in the cut
    atomicAdd(counts.instancesCulled, 1u);
    return;
  }
  if (lo == 0u) emit(i, full.firstCluster, full.clusterCount);
  if (hi > 0u) {
    const uint first = levels[c.levels.x + max(lo, 1u)].firstCluster;
    emit(i, first, levels[c.levels.x + hi].firstCluster + levels[c.levels.x + hi].clusterCount - first);
  }
}
