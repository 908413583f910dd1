// Clusters: the unit of GPU-driven culling and of the compute rasteriser. A cluster is up to
// CLUSTER_MAX_TRIANGLES triangles of one draw, contiguous in that draw's index range, so a triangle's id
// (instance, firstTriangle + local index) is the same gl_PrimitiveID the hardware path sees. Built at bake time
// (meshoptimizer, stored in .rtrscene) or at load; the mesh's index buffer is reordered cluster by cluster.
#ifndef RTR_SHADERS_SHARED_CLUSTER_H
#define RTR_SHADERS_SHARED_CLUSTER_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace rtr::shader {
using namespace glm;
typedef uint32_t uint;
#endif

#define CLUSTER_MAX_VERTICES 64
#define CLUSTER_MAX_TRIANGLES 124

// Storage buffer, std430, 48 bytes. GpuScene stores one record per cluster of a mesh, bounds in the mesh's
// space; the culling pass places them by each instance (GpuCullInstance) and lists (instance, record)
// pairs (docs/culling.md). render::gpuClusters makes one record per (instance, cluster), placed on the CPU,
// for record() without instances (the tests, rtr-bench-cull).
struct GpuCluster {
  vec4 sphere;         // xyz centre, w radius
  vec4 cone;           // xyz axis (unit), w cutoff: back-facing when dot(c - eye, axis) >= w |c - eye| + radius
                       // (c the sphere's centre; meshoptimizer's conservative test); w >= 1 never culls
  uint instance;       // its GpuInstance (frame.h) in gpuClusters' records; unused in GpuScene's (per mesh)
  uint firstTriangle;  // of the draw: the triangle's primitive id is firstTriangle + local index
  uint triangleCount;  // 1..CLUSTER_MAX_TRIANGLES
  uint flags;          // CLUSTER_* below
};
#define CLUSTER_ALPHA_MASKED 1u  // its material cuts out by texture alpha
#define CLUSTER_DOUBLE_SIDED 2u  // never back-face culled (cone disabled)
#define CLUSTER_MIRRORED 4u      // its instance's determinant is negative: front faces are clockwise on screen

// Storage buffer, std430, 48 bytes, parallel to the GpuClusters (only for a scene with a cluster
// hierarchy, docs/virtual-geometry.md): the level-of-detail choice's spheres and errors, in the space of
// the GpuCluster's bounds.
struct GpuClusterLod {
  vec4 sphere;        // where `error` applies (the simplification that made the cluster)
  vec4 parentSphere;  // where `parentError` applies (the one that replaced it)
  vec4 error;         // x its error, y its parent's (LOD_ERROR_INFINITE: a root), zw 0
};

// One per instance that has clusters (storage buffer, std430, 64 bytes): what the culling pass tests
// before the instance's clusters, and how it places them (docs/culling.md).
struct GpuCullInstance {
  vec4 sphere;     // scene space: holds the culling sphere of every one of its clusters
  vec4 lodSphere;  // scene space: holds every level-of-detail sphere of its clusters (own and parent's)
  uvec4 levels;    // x: its mesh's first GpuCullNode, the root of level 0's tree (the other levels' roots
                   // follow), y: how many levels, z: its GpuInstance (CULL_RECORD_INSTANCE: records placed
                   // already, each names its own), w: its history slots' offset (a record's slot is
                   // record + w, modulo 2^32)
  vec4 placement;  // x: the transform's largest stretch (radii, errors), y: 1 where it is a similarity
                   // (the cone turns with it; else dropped), z: 1 for the identity (records used as stored)
};
#define CULL_RECORD_INSTANCE 0xFFFFFFFFu

// A node of the tree over one level of a mesh's clusters (storage buffer, std430, 48 bytes), in the mesh's
// space: a leaf is a run of up to CULL_GROUP_SIZE consecutive records, an inner node up to
// CULL_NODE_CHILDREN consecutive nodes. The culling pass descends a node only where one of the clusters
// below can be listed (docs/culling.md, "The hierarchy").
struct GpuCullNode {
  vec4 sphere;           // holds the culling spheres of the clusters below
  vec4 lodSphere;        // holds their level-of-detail spheres (own, and parents' where they have one)
  float minError;        // the least error of the clusters below
  float maxParentError;  // the largest error of their parents (LOD_ERROR_INFINITE where one is a root)
  uint first;            // a leaf: its first record; else its first child node
  uint count;            // records or children, | CULL_NODE_LEAF for a leaf
};
#define CULL_NODE_LEAF 0x80000000u
#define CULL_NODE_CHILDREN 8u
#define CULL_LEAF_SIZE 16u  // records of a leaf
#define CULL_MAX_DEPTH 8u  // node levels of one tree: 64 * 8^7 clusters a level at most

#ifdef __cplusplus
static_assert(sizeof(GpuCluster) == 48 && sizeof(GpuClusterLod) == 48 && sizeof(GpuCullInstance) == 64 &&
              sizeof(GpuCullNode) == 48);
}  // namespace rtr::shader
#endif
#endif
