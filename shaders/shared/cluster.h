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
  uvec4 levels;    // x: its mesh's first GpuCullLevel, y: how many (level 0 first), z: its GpuInstance
                   // (CULL_RECORD_INSTANCE: records placed already, each names its own), w: its history
                   // slots' offset (a record's slot is record + w, modulo 2^32)
  vec4 placement;  // x: the transform's largest stretch (radii, errors), y: 1 where it is a similarity
                   // (the cone turns with it; else dropped), z: 1 for the identity (records used as stored)
};
#define CULL_RECORD_INSTANCE 0xFFFFFFFFu

// One level of a mesh's clusters (storage buffer, std430, 16 bytes), errors in the mesh's space: the
// level window (docs/virtual-geometry.md) skips a level none of whose clusters can be in the cut.
struct GpuCullLevel {
  uint firstCluster;     // its records, contiguous; the levels above 0 follow one another
  uint clusterCount;
  float minError;        // the least error of its clusters
  float maxParentError;  // the largest error of their parents (LOD_ERROR_INFINITE where one is a root)
};

#ifdef __cplusplus
static_assert(sizeof(GpuCluster) == 48 && sizeof(GpuClusterLod) == 48 && sizeof(GpuCullInstance) == 64 &&
              sizeof(GpuCullLevel) == 16);
}  // namespace rtr::shader
#endif
#endif
