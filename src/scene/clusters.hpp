#pragma once
// Clusters (meshlets) of a mesh: the unit of GPU-driven culling and of the compute rasteriser
// (shaders/shared/cluster.h has the GPU record and the culling rules). Built with meshoptimizer at bake
// time or at load; building reorders the mesh's index buffer so that each cluster's triangles are
// contiguous, which keeps a triangle's primitive id equal to firstTriangle + its index in the cluster.
#include <meshoptimizer.h>

#include "scene/scene.hpp"

namespace rtr {

// Splits `mesh` into clusters of at most 64 vertices and 124 triangles (big meshes in pieces of 65 536
// triangles on all cores, each piece clustered on its own), replacing mesh.clusters and
// reordering mesh.indices cluster by cluster (every triangle kept, winding unchanged). `backfaceCone`
// false (alpha-masked or double-sided materials) stores a cone that never culls (cutoff 1).
void buildClusters(Mesh& mesh, bool backfaceCone);

// A cluster's bounds (meshopt_computeClusterBounds) as the loaders accept them: meshoptimizer skips
// zero-area triangles, so a cluster of such triangles gets a zero cone axis with cutoff 0 and a sphere
// of radius 0 (seen in the 100M-triangle temple's hierarchy); here the sphere always holds every vertex
// and a cone that is no cone, or `backfaceCone` false, gets cutoff 1 (never culls).
meshopt_Bounds clusterBounds(const uint32_t* indices, size_t count, const glm::vec3* positions, size_t vertexCount,
                             bool backfaceCone);

// Whether a mesh of this material may be back-face culled by its clusters' cones.
bool conesCull(const Material& material);

// Builds the clusters of every mesh that has triangles and none, on `threads` threads (0: all cores; the
// result is the same for any count); returns how many meshes it built.
size_t buildMissingClusters(Scene& scene, unsigned threads = 0);

}  // namespace rtr
