#pragma once
// A cluster hierarchy for continuous level of detail (docs/virtual-geometry.md): the mesh's clusters,
// then groups of neighbouring clusters simplified to half their triangles with the group's outer border
// locked and split into clusters again, level by level up to a root. Each cluster keeps the error of the
// simplification that made it and of the one that replaced it, with spheres that bound where the error
// is, so a view chooses its cut with shaders/shared/cluster_lod.h's rule and no CPU work. No GPU here.
#include <cstdint>
#include <span>
#include <vector>

#include "scene/scene.hpp"

namespace rtr {

// The longest edge a simplification makes, in units of the error it reports: a triangle the simplifier
// made spans at most this many times the threshold in pixels where it is drawn. Its geometric error
// alone lets flat and ruled surfaces (floors, walls, columns) collapse into triangles of any size. With 8
// the slivers a simplification with locked borders makes (they span its group) held whole groups under
// a few pixels, and the temple's floor and columns stayed at full detail; 32 halves the 10M temple's 4K
// cut with the tile pass's work within 2 % (docs/virtual-geometry.md, measured with rtr-lod-cut). Bounding
// the made triangles' area instead halves the cut again, but on the H200 the large-triangle pass then
// costs what the raster saves (docs/virtual-geometry.md, "The 100M cut's density, found").
constexpr float kLodEdgePerError = 32.0f;

// What the build did with one group of clusters (rtr-lod-cut prints them per level): how far it simplified
// and which of the error's two terms decided (docs/virtual-geometry.md).
struct LodGroupStats {
  uint32_t level = 0;  // of the clusters grouped; the result is level + 1
  uint32_t clusters = 0, trianglesIn = 0;
  uint32_t trianglesOut = 0;     // 0: stuck (its clusters are grouped again at the next level)
  float simplifierError = 0.0f;  // object space, what the simplifier reports
  float edgeError = 0.0f;        // the size term: longest new edge / kEdgePerError
  float radius = 0.0f;           // of the group's sphere
  bool welded = false;           // simplified over one vertex per position (stuck with its seams kept)
};

// The hierarchy of `mesh` (positions, indices and its clusters, which become level 0: build them first,
// scene/clusters.hpp). Deterministic, whatever the thread count (0: one per core). A group whose
// simplification cannot remove a sixth of its triangles is stuck: its clusters are grouped again with the
// next level's. Stuck again, it is simplified over one vertex per position (its own seams given up: where
// many vertices meet at a point the simplifier locks them); what is left when no group simplifies, or
// after 64 levels, are roots.
// `backfaceCone` as buildClusters' (false: the clusters above level 0 get cones that never cull).
// `stats`, where given, receives one record per group, level by level.
ClusterLod buildClusterLod(const Mesh& mesh, bool backfaceCone = true, unsigned threads = 0,
                           std::vector<LodGroupStats>* stats = nullptr);
// Builds the hierarchy of every mesh that has clusters and none (rtr-bake); returns how many.
size_t buildMissingClusterLods(Scene& scene, unsigned threads = 0);

// The vertex indices of cluster `c`'s triangles: the mesh's own (level 0) or the hierarchy's.
std::span<const uint32_t> lodTriangles(const Mesh& mesh, const LodCluster& c);

}  // namespace rtr
