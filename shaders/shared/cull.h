// Cluster culling: the tests the compute pass (shaders/render/cull.comp) applies to each GpuCluster, in
// the subset of GLSL that C++ with glm also compiles, so the CPU reference runs the very same formulas.
// Keep to the common subset (shaders/shared/brdf.h says which). Depth is Vulkan's [0, 1], near 0 (projectionMatrix in src/core/camera.hpp), compared LESS.
#ifndef RTR_SHADERS_SHARED_CULL_H
#define RTR_SHADERS_SHARED_CULL_H

#include "cluster.h"
#include "cluster_lod.h"
#include "shared.h"

#ifdef __cplusplus
namespace rtr::shader {
#endif

#define CULL_GROUP_SIZE 64
// The cluster step's workgroup tests this many chunks (tree leaves, up to CULL_LEAF_SIZE records each).
#define CULL_CHUNKS_PER_GROUP (CULL_GROUP_SIZE / CULL_LEAF_SIZE)
#define HIZ_GROUP_SIZE 8
// The fused pyramid (hiz_fused.glsl): a workgroup of HIZ_FUSED_SIDE² threads per tile of HIZ_TILE ×
// HIZ_TILE source texels writes the HIZ_FUSED_LEVELS levels above it (HIZ_TILE = 2^HIZ_FUSED_LEVELS, at
// most 6 levels).
#define HIZ_FUSED_SIDE 8
#define HIZ_TILE 32
#define HIZ_FUSED_LEVELS 5

// CullPush::flags: which tests run.
#define CULL_FRUSTUM 1u
#define CULL_CONE 2u       // perspective cameras only: the test assumes rays from the eye
#define CULL_OCCLUSION 4u  // against the depth pyramid bound to the pass
#define CULL_LOD 8u        // the level-of-detail cut (cluster_lod.h's lodSelected) over the GpuClusterLods
#define CULL_NODES 16u     // prune the tree's nodes (else every node is descended: the flat test, for tests)

// CullPush::phase. Two-phase occlusion culling (docs/culling.md): EARLY passes the clusters visible last
// frame (per the history buffer) through frustum and cone only; once they are drawn and the pyramid built
// from that depth, LATE tests every cluster against it, lists the visible ones not drawn early, and
// rewrites the history. SINGLE tests every cluster once and leaves the history alone.
#define CULL_SINGLE 0u
#define CULL_EARLY 1u
#define CULL_LATE 2u

// Why a cluster was culled: the index of its counter after the indirect dispatch arguments.
#define CULL_VISIBLE 0u
#define CULL_BY_FRUSTUM 1u
#define CULL_BY_CONE 2u
#define CULL_BY_OCCLUSION 3u
#define CULL_BY_LOD 4u  // not in the cut at this view and threshold (tested first)

// The visible list: uvec2 (GpuInstance, GpuCluster record) per entry; LATE appends after EARLY's entries,
// so an entry's position names one cluster of one instance for the whole frame (the rasteriser's tile and
// hand-off lists keep positions).
// The counts buffer: VkDispatchIndirectCommand {visible clusters, 1, 1}, then the culled counts by reason.
// Over CullPush::maxGroupsX visible clusters the dispatch is two-dimensional, {maxGroupsX, rows, 1}: a
// workgroup's list entry is then gl_WorkGroupID.y * maxGroupsX + gl_WorkGroupID.x (below `listed`).
// The pass runs in steps: instances, then the tree over each level of their meshes' clusters depth by
// depth (cull_instances.comp), then the chunks of clusters of the leaves reached (cull.comp,
// CULL_CHUNKS_PER_GROUP chunks a workgroup), dispatched from chunkDispatch the same way.
struct CullCounts {
  uint dispatch[3];
  uint culled[4];         // frustum, cone (back-facing), occlusion, level of detail
  uint listed;            // entries this pass added to the visible list, from listBase on
  uint triangles;         // of the listed clusters
  uint tested;            // clusters the cluster step visited: those of the instances kept
  uint instancesCulled;   // instances culled whole by the frustum (one test each, none of their clusters)
  uint chunks;            // runs of up to CULL_LEAF_SIZE clusters (tree leaves), CULL_CHUNKS_PER_GROUP a workgroup
  uint chunkDispatch[3];  // its indirect dispatch
  uint listBase;          // where this pass's entries start: 0, or for LATE the entries EARLY listed
  uint nodes;             // tree nodes tested
  uint pad0, pad1, pad2;
};

// The tree's work queues, one per depth (CULL_MAX_DEPTH of them, 32 bytes each): (instance, node) items
// at queue `base`, `count` of them; dispatch, the indirect dispatch of the step that tests them (threads
// of CULL_GROUP_SIZE, two-dimensional past maxGroupsX workgroups).
struct CullQueue {
  uint dispatch[3];
  uint count;
  uint base;
  uint pad0, pad1, pad2;
};

struct CullPush {  // 128 bytes
  mat4 viewProj;
  vec4 eye;          // xyz
  uint count;        // instances (GpuCullInstance) to test
  uint flags;        // CULL_*
  uint width;        // the depth source's size in pixels (the pyramid's level 0 is half of it, rounded up)
  uint height;
  uint pyramidLevels;
  uint phase;        // CULL_SINGLE, CULL_EARLY or CULL_LATE
  uint maxGroupsX;   // the device's maxComputeWorkGroupCount[0] (at most 65535): wider lists go 2D
  float lodThreshold;   // CULL_LOD: pixels of projected error
  float pixelsPerUnit;  // image height / (2 tan(fovY / 2))
  float zNear;
  uint clusters;  // without instances (CULL_RECORD_INSTANCE): the records to test; else 0
  uint depth;     // cull_instances.comp: CULL_INSTANCE_STEP, or the tree depth whose queue it tests
};
#define CULL_INSTANCE_STEP 0xFFFFFFFFu

// hiz_fused.glsl's push constants: the source's size (pixels, or the level below the first one written)
// and how many levels this dispatch writes (1 to HIZ_FUSED_LEVELS).
struct HizPush {
  uint width;
  uint height;
  uint levels;
  uint pad;
};

RTR_FN vec4 matrixRow(mat4 m, int i) { return vec4(m[0][i], m[1][i], m[2][i], m[3][i]); }

// The sphere lies wholly outside one of the six clip planes (left, right, bottom, top, near, far).
RTR_FN bool frustumCulls(vec4 sphere, mat4 viewProj) {
  const vec4 r0 = matrixRow(viewProj, 0), r1 = matrixRow(viewProj, 1), r2 = matrixRow(viewProj, 2),
             r3 = matrixRow(viewProj, 3);
  vec4 planes[6];
  planes[0] = r3 + r0;
  planes[1] = r3 - r0;
  planes[2] = r3 + r1;
  planes[3] = r3 - r1;
  planes[4] = r2;
  planes[5] = r3 - r2;
  for (int i = 0; i < 6; ++i) {
    const vec3 n = vec3(planes[i].x, planes[i].y, planes[i].z);
    if (dot(n, vec3(sphere.x, sphere.y, sphere.z)) + planes[i].w < -sphere.w * length(n)) return true;
  }
  return false;
}

// Every triangle of the cluster faces away from the eye (meshoptimizer's sphere-based cone test).
RTR_FN bool coneCulls(vec4 sphere, vec4 cone, vec3 eye) {
  const vec3 d = vec3(sphere.x, sphere.y, sphere.z) - eye;
  return cone.w < 1.0f && dot(d, vec3(cone.x, cone.y, cone.z)) >= cone.w * length(d) + sphere.w;
}

// The sphere's scene-space bounding cube projected: the pixels it may cover (min x, min y, max x, max y,
// clamped to the image) and the nearest depth of any of its points. inFront 0: a corner lies behind the
// eye, so the box has no projection (never occlusion-culled).
struct ProjectedBox {
  ivec4 pixels;
  float nearestDepth;
  uint inFront;
};

RTR_FN ProjectedBox projectBox(vec4 sphere, mat4 viewProj, uint width, uint height) {
  ProjectedBox b;
  b.inFront = 1u;
  b.nearestDepth = 1.0f;
  vec2 lo = vec2(1e30f, 1e30f), hi = vec2(-1e30f, -1e30f);
  for (int i = 0; i < 8; ++i) {
    const vec3 corner = vec3(sphere.x + ((i & 1) != 0 ? sphere.w : -sphere.w),
                             sphere.y + ((i & 2) != 0 ? sphere.w : -sphere.w),
                             sphere.z + ((i & 4) != 0 ? sphere.w : -sphere.w));
    const vec4 clip = viewProj * vec4(corner, 1.0f);
    if (clip.w <= 1e-6f) b.inFront = 0u;
    const vec3 ndc = vec3(clip.x, clip.y, clip.z) / max(clip.w, 1e-6f);
    b.nearestDepth = min(b.nearestDepth, max(ndc.z, 0.0f));
    lo = min(lo, vec2(ndc.x, ndc.y));
    hi = max(hi, vec2(ndc.x, ndc.y));
  }
  // Pixel p covers [p, p + 1): a sample at any pixel centre inside [lo, hi] lies in the pixels
  // floor(lo) .. floor(hi).
  const vec2 size = vec2(float(width), float(height));
  const vec2 pLo = clamp((lo * 0.5f + 0.5f) * size, vec2(0.0f, 0.0f), size - 1.0f);
  const vec2 pHi = clamp((hi * 0.5f + 0.5f) * size, vec2(0.0f, 0.0f), size - 1.0f);
  b.pixels = ivec4(int(floor(pLo.x)), int(floor(pLo.y)), int(floor(pHi.x)), int(floor(pHi.y)));
  return b;
}

// A record's sphere (xyz centre, w radius) placed by an instance: the centre by the transform, the radius
// by its largest stretch (GpuCullInstance::placement.x).
RTR_FN vec4 placeSphere(mat4 transform, float stretch, vec4 s) {
  const vec4 c = transform * vec4(s.x, s.y, s.z, 1.0f);
  return vec4(c.x, c.y, c.z, s.w * stretch);
}

// The depth pyramid: level 0 is half the image and each level half the last, rounding down (Vulkan's mip
// sizes); texel t of a level holds the farthest of the texels 2t and 2t + 1 below it and, for the last
// texel of an odd-sized level below, 2t + 2 too. So texel min(p >> (L + 1), size_L - 1) of level L covers
// pixel p, at every level and for any image size.

// The finest pyramid level whose texels cover the box's pixels with at most span × span texels.
RTR_FN int pyramidLevelFor(ivec4 px, int levels, int span) {
  int shift = 1;
  while (shift < levels && (((px.z >> shift) - (px.x >> shift)) >= span || ((px.w >> shift) - (px.y >> shift)) >= span))
    ++shift;
  return shift - 1;
}

// The occlusion test reads up to 4 × 4 texels: one level finer than 2 × 2, where a box's texels reach less
// far past it (rtr-lod-cut --fates: on the 1M-triangle grid's three views the pass then lists 11-52 % fewer
// triangles; docs/culling.md).
#define CULL_PYRAMID_SPAN 4
// The pyramid's levels at most: at 4K, level 6 has texels of 128 pixels (the five below it, each a dispatch
// and a barrier, would serve only boxes wider than ~512 pixels, which read up to their width / 128 texels a row).
#define CULL_PYRAMID_MAX_LEVELS 7u
RTR_FN int pyramidLevel(ivec4 px, int levels) { return pyramidLevelFor(px, levels, CULL_PYRAMID_SPAN); }

// The texels (min x, min y, max x, max y) of level `level`, of size `levelSize`, that cover the pixels.
RTR_FN ivec4 pyramidTexels(ivec4 px, int level, ivec2 levelSize) {
  const ivec4 t = px >> (level + 1);
  return ivec4(min(t.x, levelSize.x - 1), min(t.y, levelSize.y - 1), min(t.z, levelSize.x - 1), min(t.w, levelSize.y - 1));
}

#ifdef __cplusplus
static_assert(sizeof(CullPush) == 128 && sizeof(CullCounts) == 80 && sizeof(CullQueue) == 32 && sizeof(HizPush) == 16);
}  // namespace rtr::shader
#endif
#endif
