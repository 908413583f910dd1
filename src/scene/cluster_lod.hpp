#pragma once
// A cluster hierarchy for continuous level of detail (docs/virtual-geometry.md): the mesh's clusters,
// then groups of neighbouring clusters simplified to half their triangles with the group's outer border
// locked and split into clusters again, level by level up to a root. Each cluster keeps the error of the
// simplification that made it and of the one that replaced it, with spheres that bound where the error
// is, so a view chooses its cut with shaders/shared/cluster_lod.h's rule and no CPU work. No GPU here.
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "scene/scene.hpp"

namespace rtr {

struct LodCluster {
  uint32_t firstIndex = 0, triangleCount = 0;  // in ClusterLod::indices
  uint32_t level = 0;                          // 0: the mesh's own triangles
  glm::vec3 center{0.0f};                      // bounds of its triangles (culling)
  float radius = 0.0f;
  glm::vec4 sphere{0.0f};     // where `error` applies (the group that made it; level 0: its own bounds)
  float error = 0.0f;         // object-space error of the simplification that made it (level 0: 0)
  glm::vec4 parentSphere{0.0f};
  float parentError = 0.0f;   // of the simplification that replaced it; LOD_ERROR_INFINITE for a root
};

struct ClusterLod {
  std::vector<uint32_t> indices;  // triangles of every level, cluster by cluster; the mesh's vertices
  std::vector<LodCluster> clusters;
  uint32_t levels = 0;
  size_t triangles(uint32_t level) const;  // of that level's clusters
};

// The hierarchy of `mesh` (positions and indices). Deterministic. Groups whose simplification cannot
// remove a sixth of their triangles (locked borders everywhere) stop there as roots.
ClusterLod buildClusterLod(const Mesh& mesh);

}  // namespace rtr
