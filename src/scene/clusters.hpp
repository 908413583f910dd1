#pragma once
// Clusters (meshlets) of a mesh: the unit of GPU-driven culling and of the compute rasteriser
// (shaders/shared/cluster.h has the GPU record and the culling rules). Built with meshoptimizer at bake
// time or at load; building reorders the mesh's index buffer so that each cluster's triangles are
// contiguous, which keeps a triangle's primitive id equal to firstTriangle + its index in the cluster.
#include <meshoptimizer.h>

#include <condition_variable>
#include <mutex>
#include <vector>

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

// How far the clusters of each mesh are built, for a writer that follows the build on another thread
// (rtr-bake writes the file beside the clusters: writeRtrScene's gate). A mesh's triangles are final in
// order, piece by piece, as the pieces before them are done too; its clusters once all are.
class ClusterProgress {
 public:
  // The meshes buildMissingClusters will build (triangles and no clusters) have nothing final yet; the
  // others are final. Their indices are made writable here (a view copied now, before a reader looks).
  explicit ClusterProgress(Scene& scene);
  // Returns once triangles [0, triangles) of mesh `mesh` are in their final order and, for all of its
  // triangles, its clusters are set; for mesh >= the mesh count, once finish() is called. Throws
  // rtr::Error once stop() is called (the build failed).
  void wait(size_t mesh, size_t triangles);
  size_t finalTriangles(size_t mesh);  // how many of its triangles are final now
  void finish();                       // everything built (the hierarchy too): every wait returns
  void stop();                         // the build failed: waiters throw

  // Used by the build: piece `piece` of mesh `mesh` (pieces numbered in index order, `pieces` in all) is
  // done up to triangle `end`; returns true to the one caller that completes the mesh, which then calls
  // meshDone(mesh) once its clusters are set.
  bool pieceDone(size_t mesh, size_t piece, size_t pieces, size_t end);
  void meshDone(size_t mesh);

 private:
  struct State {
    size_t final = 0, triangles = 0, next = 0;  // triangles final; in all; the first piece not yet done
    std::vector<size_t> ends;                   // per piece: its end once done, else 0
    bool complete = false;
  };
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<State> meshes_;
  bool finished_ = false, stopped_ = false;
};

// Builds the clusters of every mesh that has triangles and none, on `threads` threads (0: all cores; the
// result is the same for any count); returns how many meshes it built. With `progress` (made from this
// scene), each mesh's triangles are reported final as their pieces end (stop() is called if it throws).
size_t buildMissingClusters(Scene& scene, unsigned threads = 0, ClusterProgress* progress = nullptr);

}  // namespace rtr
