#version 460
// Culling before the clusters, one thread per item. The instance step (pc.depth = CULL_INSTANCE_STEP):
// one thread per instance (GpuCullInstance, cluster.h); an instance whose sphere lies outside the frustum
// is culled whole, one test for all its clusters; the others queue the roots of their mesh's level trees
// (level 0's only without the level-of-detail cut). The node steps, one per depth: one thread per queued
// (instance, node); a node is descended only if it is in the frustum and, with the cut, some cluster below
// can be in it (its least error, projected from the farthest point of its sphere, at most the threshold,
// and its parents' largest, from the nearest, above it; docs/culling.md); its children go to the next
// depth's queue, a leaf's records to the chunks (up to CULL_LEAF_SIZE), CULL_CHUNKS_PER_GROUP to a
// workgroup of the cluster step (cull.comp), dispatched indirectly from counts.chunkDispatch. Without
// instances (pc.clusters > 0), the instance step makes the chunks of the records, one a thread.
#extension GL_GOOGLE_include_directive : require
#include "cull.h"
#include "frame.h"
#include "cull_subgroup.glsl"

layout(local_size_x = CULL_GROUP_SIZE) in;

layout(set = 0, binding = 1, std430) buffer Counts { CullCounts counts; };
layout(set = 0, binding = 6, std430) readonly buffer Instances { GpuCullInstance cullInstances[]; };
layout(set = 0, binding = 7, std430) writeonly buffer Chunks { uvec4 chunks[]; };  // instance, first record, count
layout(set = 0, binding = 8, std430) readonly buffer Nodes { GpuCullNode nodes[]; };
layout(set = 0, binding = 9, std430) readonly buffer Placements { GpuInstance instances[]; };
layout(set = 0, binding = 10, std430) buffer Queues { CullQueue queues[CULL_MAX_DEPTH]; };
layout(set = 0, binding = 11, std430) buffer Items { uvec2 items[]; };  // (GpuCullInstance, node)

layout(push_constant) uniform Push { CullPush pc; };

// Raises an indirect dispatch (workgroups of `per` items, two-dimensional past maxGroupsX) to cover item
// `last` (0xFFFFFFFF: nothing to cover).
#define CULL_COVER(dispatch, last, per)                                      \
  if (last != 0xFFFFFFFFu) {                                                 \
    const uint group_ = last / (per), maxX_ = max(pc.maxGroupsX, 1u);        \
    atomicMax(dispatch[0], min(group_ + 1u, maxX_));                         \
    atomicMax(dispatch[1], group_ / maxX_ + 1u);                             \
  }

// A leaf's records (up to CULL_LEAF_SIZE) as one chunk of the cluster step, where `on`.
void emit(bool on, uint instance, uint first, uint count) {
  uint k, last;
  CULL_RESERVE(counts.chunks, on ? 1u : 0u, k, last);
  CULL_COVER(counts.chunkDispatch, last, CULL_CHUNKS_PER_GROUP);
  CULL_COUNT(counts.tested, on ? count : 0u);
  if (on) chunks[k] = uvec4(instance, first, count, 0u);
}

// Nodes [first, first + count) of `instance` into the queue of `depth` (count 0: none).
void enqueue(uint depth, uint instance, uint first, uint count) {
  uint n, last;
  CULL_RESERVE(queues[depth].count, count, n, last);
  CULL_COVER(queues[depth].dispatch, last, CULL_GROUP_SIZE);
  for (uint k = 0u; k < count; ++k) items[queues[depth].base + n + k] = uvec2(instance, first + k);
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
  if (pc.depth == CULL_INSTANCE_STEP && pc.clusters > 0u) {  // records placed already: one chunk a thread
    const uint at = gl_GlobalInvocationID.x * CULL_LEAF_SIZE;
    if (at >= pc.clusters) return;
    emit(true, 0u, at, min(CULL_LEAF_SIZE, pc.clusters - at));
    return;
  }
  if (pc.depth == CULL_INSTANCE_STEP) {
    const uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    const GpuCullInstance c = cullInstances[i];
    // Its clusters' spheres lie in its sphere: a plane that has it wholly outside has them too.
    const bool culled = (pc.flags & CULL_FRUSTUM) != 0u && frustumCulls(c.sphere, pc.viewProj);
    CULL_COUNT(counts.instancesCulled, culled ? 1u : 0u);
    enqueue(0u, i, c.levels.x, culled ? 0u : (pc.flags & CULL_LOD) != 0u ? c.levels.y : 1u);
    return;
  }
  const uint k = (gl_WorkGroupID.y * max(pc.maxGroupsX, 1u) + gl_WorkGroupID.x) * CULL_GROUP_SIZE + gl_LocalInvocationID.x;
  if (k >= queues[pc.depth].count) return;
  const uvec2 item = items[queues[pc.depth].base + k];
  const GpuCullNode node = nodes[item.y];
  CULL_COUNT(counts.nodes, 1u);
  const bool on = descend(node, cullInstances[item.x]), leaf = (node.count & CULL_NODE_LEAF) != 0u;
  emit(on && leaf, item.x, node.first, node.count & ~CULL_NODE_LEAF);
  if (pc.depth + 1u < CULL_MAX_DEPTH) enqueue(pc.depth + 1u, item.x, node.first, on && !leaf ? node.count : 0u);
}
