#version 460
// Culling before the clusters, one thread per item. The instance step (pc.depth = CULL_INSTANCE_STEP):
// one thread per instance (GpuCullInstance, cluster.h); an instance whose sphere lies outside the frustum
// is culled whole, one test for all its clusters; the others queue the roots of their mesh's level trees
// (level 0's only without the level-of-detail cut). The node steps, one per depth: one thread per queued
// (instance, node); a node is descended only if it is in the frustum and, with the cut, some cluster below
// can be in it (its least error, projected from the farthest point of its sphere, at most the threshold,
// and its parents' largest, from the nearest, above it; docs/culling.md); its children go to the next
// depth's queue, a leaf's clusters to the chunks (up to CULL_GROUP_SIZE), one workgroup each of the
// cluster step (cull.comp), dispatched indirectly from counts.chunkDispatch.
#extension GL_GOOGLE_include_directive : require
#include "cull.h"
#include "frame.h"

layout(local_size_x = CULL_GROUP_SIZE) in;

layout(set = 0, binding = 1, std430) buffer Counts { CullCounts counts; };
layout(set = 0, binding = 6, std430) readonly buffer Instances { GpuCullInstance cullInstances[]; };
layout(set = 0, binding = 7, std430) writeonly buffer Chunks { uvec4 chunks[]; };  // instance, first record, count
layout(set = 0, binding = 8, std430) readonly buffer Nodes { GpuCullNode nodes[]; };
layout(set = 0, binding = 9, std430) readonly buffer Placements { GpuInstance instances[]; };
layout(set = 0, binding = 10, std430) buffer Queues { CullQueue queues[CULL_MAX_DEPTH]; };
layout(set = 0, binding = 11, std430) buffer Items { uvec2 items[]; };  // (GpuCullInstance, node)

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

void enqueue(uint depth, uint instance, uint first, uint count) {
  const uint n = atomicAdd(queues[depth].count, count), maxX = max(pc.maxGroupsX, 1u);
  for (uint k = 0u; k < count; ++k) items[queues[depth].base + n + k] = uvec2(instance, first + k);
  const uint lastGroup = (n + count - 1u) / CULL_GROUP_SIZE;
  atomicMax(queues[depth].dispatch[0], min(lastGroup + 1u, maxX));
  atomicMax(queues[depth].dispatch[1], lastGroup / maxX + 1u);
}

// Whether some cluster below `node`, placed by the instance, can be listed (sphere and errors placed).
bool descend(GpuCullNode node, GpuCullInstance ci) {
  if ((pc.flags & CULL_NODES) == 0u) return true;
  vec4 sphere = node.sphere, lodSphere = node.lodSphere;
  float minError = node.minError, maxParentError = node.maxParentError;
  if (ci.placement.z == 0.0f) {
    const mat4 m = instances[ci.levels.z].transform;
    sphere = placeSphere(m, ci.placement.x, sphere);
    lodSphere = placeSphere(m, ci.placement.x, lodSphere);
    minError *= ci.placement.x;
    if (maxParentError < LOD_ERROR_INFINITE) maxParentError *= ci.placement.x;
  }
  // Room for rounding: a cluster's placed sphere lies in its node's, up to the transform's rounding.
  sphere.w = sphere.w * 1.001f + 1e-5f * length(sphere.xyz);
  if ((pc.flags & CULL_FRUSTUM) != 0u && frustumCulls(sphere, pc.viewProj)) return false;
  if ((pc.flags & CULL_LOD) == 0u) return true;
  // Every cluster's distance term of lodProjectedError (cluster_lod.h) lies in [near, far]: its spheres
  // lie in lodSphere. A little slack for rounding.
  const float d = length(lodSphere.xyz - pc.eye.xyz);
  const float near = max(d - lodSphere.w, pc.zNear) * 0.999f, far = max(d + lodSphere.w, pc.zNear) * 1.001f;
  return minError * pc.pixelsPerUnit / far <= pc.lodThreshold &&
         (maxParentError >= LOD_ERROR_INFINITE || maxParentError * pc.pixelsPerUnit / near > pc.lodThreshold);
}

void main() {
  if (pc.depth == CULL_INSTANCE_STEP) {
    const uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    const GpuCullInstance c = cullInstances[i];
    // Its clusters' spheres lie in its sphere: a plane that has it wholly outside has them too.
    if ((pc.flags & CULL_FRUSTUM) != 0u && frustumCulls(c.sphere, pc.viewProj)) {
      atomicAdd(counts.instancesCulled, 1u);
      return;
    }
    if (c.levels.z == CULL_RECORD_INSTANCE) emit(i, 0u, pc.clusters);  // records as they are, no tree
    else enqueue(0u, i, c.levels.x, (pc.flags & CULL_LOD) != 0u ? c.levels.y : 1u);
    return;
  }
  const uint k = (gl_WorkGroupID.y * max(pc.maxGroupsX, 1u) + gl_WorkGroupID.x) * CULL_GROUP_SIZE + gl_LocalInvocationID.x;
  if (k >= queues[pc.depth].count) return;
  const uvec2 item = items[queues[pc.depth].base + k];
  const GpuCullInstance ci = cullInstances[item.x];
  const GpuCullNode node = nodes[item.y];
  atomicAdd(counts.nodes, 1u);
  if (!descend(node, ci)) return;
  if ((node.count & CULL_NODE_LEAF) != 0u) emit(item.x, node.first, node.count & ~CULL_NODE_LEAF);
  else if (pc.depth + 1u < CULL_MAX_DEPTH) enqueue(pc.depth + 1u, item.x, node.first, node.count);
}
