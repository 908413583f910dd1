#version 460
// Cluster culling, second step: CULL_CHUNKS_PER_GROUP chunks of clusters that cull_instances.comp kept
// (a tree leaf each) per workgroup, a thread per cluster; the records (the mesh's) placed by the chunk's instance, then the level-of-detail
// cut, frustum, back-face cone and occlusion against the depth pyramid (shaders/shared/cull.h has the
// tests and the phases). Visible clusters are appended as (instance, record) to a compact list whose
// length is the size of an indirect dispatch (one workgroup per visible cluster; cull.h); culled ones are
// counted by reason. The caller zeroes the counts (x = 0, y = z = 1) before the pass.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "cull.h"
#include "frame.h"
#include "cull_subgroup.glsl"

layout(local_size_x = CULL_GROUP_SIZE) in;

layout(set = 0, binding = 0, std430) readonly buffer Clusters { GpuCluster clusters[]; };
layout(set = 0, binding = 1, std430) buffer Counts { CullCounts counts; };
layout(set = 0, binding = 2, std430) writeonly buffer Visible { uvec2 visible[]; };
layout(set = 0, binding = 3) uniform texture2D pyramid;  // R32F, farthest depth per texel (hiz.comp)
// A bit per history slot (GpuCullInstance::levels.w): visible in the last LATE pass.
layout(set = 0, binding = 4, std430) buffer History { uint history[]; };
layout(set = 0, binding = 5, std430) readonly buffer Lods { GpuClusterLod lods[]; };  // read with CULL_LOD
layout(set = 0, binding = 6, std430) readonly buffer CullInstances { GpuCullInstance cullInstances[]; };
layout(set = 0, binding = 7, std430) readonly buffer Chunks { uvec4 chunks[]; };  // instance, first record, count
layout(set = 0, binding = 9, std430) readonly buffer Instances { GpuInstance instances[]; };

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
  const uint k = (gl_WorkGroupID.y * max(pc.maxGroupsX, 1u) + gl_WorkGroupID.x) * CULL_CHUNKS_PER_GROUP +
                 gl_LocalInvocationID.x / CULL_LEAF_SIZE;
  if (k >= counts.chunks) return;
  const uvec4 chunk = chunks[k];
  const uint lane = gl_LocalInvocationID.x % CULL_LEAF_SIZE;
  if (lane >= chunk.z) return;
  const uint i = chunk.y + lane;
  const GpuCullInstance ci = cullInstances[chunk.x];
  const uint slot = i + ci.levels.w;
  const bool wasVisible = pc.phase != CULL_SINGLE && (history[slot >> 5u] & (1u << (slot & 31u))) != 0u;
  if (pc.phase == CULL_EARLY && !wasVisible) return;
  GpuCluster c = clusters[i];
  GpuClusterLod lod;
  if ((pc.flags & CULL_LOD) != 0u) lod = lods[i];
  uint instance = c.instance;
  if (ci.levels.z != CULL_RECORD_INSTANCE) {
    instance = ci.levels.z;
    if (ci.placement.z == 0.0f) {  // not the identity: place the records (the identity keeps them exact)
      const mat4 m = instances[instance].transform;
      const float s = ci.placement.x;
      c.sphere = placeSphere(m, s, c.sphere);
      // A similarity turns the cone (a mirror with it: the winding flips too); other transforms bend it.
      if (ci.placement.y == 0.0f) c.cone = vec4(0.0f, 0.0f, 1.0f, 2.0f);
      else if (c.cone.w < 1.0f) c.cone.xyz = normalize(mat3(m) * c.cone.xyz);
      if ((pc.flags & CULL_LOD) != 0u) {
        lod.sphere = placeSphere(m, s, lod.sphere);
        lod.parentSphere = placeSphere(m, s, lod.parentSphere);
        lod.error.x *= s;
        if (lod.error.y < LOD_ERROR_INFINITE) lod.error.y *= s;
      }
    }
  }
  uint reason = CULL_VISIBLE;
  if ((pc.flags & CULL_LOD) != 0u &&
      !lodSelected(lod.sphere, lod.error.x, lod.parentSphere, lod.error.y, pc.eye.xyz, pc.pixelsPerUnit, pc.zNear, pc.lodThreshold))
    reason = CULL_BY_LOD;
  else if ((pc.flags & CULL_FRUSTUM) != 0u && frustumCulls(c.sphere, pc.viewProj)) reason = CULL_BY_FRUSTUM;
  else if ((pc.flags & CULL_CONE) != 0u && coneCulls(c.sphere, c.cone, pc.eye.xyz)) reason = CULL_BY_CONE;
  else if ((pc.flags & CULL_OCCLUSION) != 0u && pc.phase != CULL_EARLY && occluded(c.sphere)) reason = CULL_BY_OCCLUSION;
  if (pc.phase == CULL_LATE && (reason == CULL_VISIBLE) != wasVisible)
    atomicXor(history[slot >> 5u], 1u << (slot & 31u));
  for (uint r = 0u; r < 4u; ++r) CULL_COUNT(counts.culled[r], reason == r + 1u ? 1u : 0u);
  const bool listed = reason == CULL_VISIBLE && !(pc.phase == CULL_LATE && wasVisible);
  uint n, last;
  CULL_RESERVE(counts.listed, listed ? 1u : 0u, n, last);
  CULL_COUNT(counts.triangles, listed ? c.triangleCount : 0u);
  if (last != 0xFFFFFFFFu) {  // one workgroup per entry, two-dimensional past maxGroupsX
    const uint maxX = max(pc.maxGroupsX, 1u);
    atomicMax(counts.dispatch[0], min(last + 1u, maxX));
    atomicMax(counts.dispatch[1], last / maxX + 1u);
  }
  if (listed) visible[counts.listBase + n] = uvec2(instance, i);
}
