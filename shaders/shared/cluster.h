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

// Storage buffer, std430, 48 bytes. One record per (instance, cluster of its mesh); bounds are in scene
// space, the mesh's cluster bounds transformed by the instance (render/cull.cpp).
struct GpuCluster {
  vec4 sphere;         // xyz centre, w radius
  vec4 cone;           // xyz axis (unit), w cutoff: back-facing when dot(c - eye, axis) >= w |c - eye| + radius
                       // (c the sphere's centre; meshoptimizer's conservative test); w >= 1 never culls
  uint instance;       // its GpuInstance (frame.h), which names the GpuDraw
  uint firstTriangle;  // of the draw: the triangle's primitive id is firstTriangle + local index
  uint triangleCount;  // 1..CLUSTER_MAX_TRIANGLES
  uint flags;          // CLUSTER_* below
};
#define CLUSTER_ALPHA_MASKED 1u  // its material cuts out by texture alpha
#define CLUSTER_DOUBLE_SIDED 2u  // never back-face culled (cone disabled)
#define CLUSTER_MIRRORED 4u      // its instance's determinant is negative: front faces are clockwise on screen

// Storage buffer, std430, 48 bytes, parallel to the GpuClusters (only for a scene with a cluster
// hierarchy, docs/virtual-geometry.md): the level-of-detail choice's spheres and errors, in scene space.
struct GpuClusterLod {
  vec4 sphere;        // where `error` applies (the simplification that made the cluster)
  vec4 parentSphere;  // where `parentError` applies (the one that replaced it)
  vec4 error;         // x its error, y its parent's (LOD_ERROR_INFINITE: a root), zw 0
};

// One per instance that has clusters (storage buffer, std430, 48 bytes): what the culling pass tests
// before the instance's clusters (docs/culling.md).
struct GpuCullInstance {
  vec4 sphere;     // scene space: holds the culling sphere of every one of its clusters
  vec4 lodSphere;  // scene space: holds every level-of-detail sphere of its clusters (own and parent's)
  uvec4 levels;    // x: its first GpuCullLevel, y: how many (level 0, its full-detail records, first)
};

// One level of an instance's clusters (storage buffer, std430, 16 bytes), errors in scene space: the
// level window (docs/virtual-geometry.md) skips a level none of whose clusters can be in the cut.
struct GpuCullLevel {
  uint firstCluster;     // its records, contiguous; the levels above 0 follow one another
  uint clusterCount;
  float minError;        // the least error of its clusters
  float maxParentError;  // the largest error of their parents (LOD_ERROR_INFINITE where one is a root)
};

#ifdef __cplusplus
static_assert(sizeof(GpuCluster) == 48 && sizeof(GpuClusterLod) == 48 && sizeof(GpuCullInstance) == 48 &&
              sizeof(GpuCullLevel) == 16);
}  // namespace rtr::shader
#endif
#endif
