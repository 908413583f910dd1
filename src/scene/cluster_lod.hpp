#pragma once
// A cluster hierarchy for continuous level of detail (docs/virtual-geometry.md): the mesh's clusters,
// then groups of neighbouring clusters simplified to half their triangles with the group's outer border
// locked and split into clusters again, level by level up to a root. Each cluster keeps the error of the
// simplification that made it and of the one that replaced it, with spheres that bound where the error
// is, so a view chooses its cut with shaders/shared/cluster_lod.h's rule and no CPU work. No GPU here.
#include <cstdint>
#include <span>

#include "scene/scene.hpp"

namespace rtr {

// The hierarchy of `mesh` (positions, indices and its clusters, which become level 0: build them first,
// scene/clusters.hpp). Deterministic, whatever the thread count (0: one per core). Groups whose
// simplification cannot remove a sixth of their triangles (locked borders everywhere) stop as roots.
// `backfaceCone` as buildClusters' (false: the clusters above level 0 get cones that never cull).
ClusterLod buildClusterLod(const Mesh& mesh, bool backfaceCone = true, unsigned threads = 0);
// Builds the hierarchy of every mesh that has clusters and none (rtr-bake); returns how many.
size_t buildMissingClusterLods(Scene& scene, unsigned threads = 0);

// The vertex indices of cluster `c`'s triangles: the mesh's own (level 0) or the hierarchy's.
std::span<const uint32_t> lodTriangles(const Mesh& mesh, const LodCluster& c);

}  // namespace rtr
