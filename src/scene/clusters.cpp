#include "scene/clusters.hpp"

#include <meshoptimizer.h>

#include <algorithm>

#include "cluster.h"
#include "core/error.hpp"
#include "scene/parallel.hpp"

namespace rtr {

void buildClusters(Mesh& mesh, bool backfaceCone) {
  constexpr size_t kMaxV = CLUSTER_MAX_VERTICES, kMaxT = CLUSTER_MAX_TRIANGLES;
  mesh.clusters.clear();
  if (mesh.indices.empty()) return;
  const float* pos = &mesh.positions[0].x;
  const size_t nv = mesh.positions.size();
  std::vector<meshopt_Meshlet> meshlets(meshopt_buildMeshletsBound(mesh.indices.size(), kMaxV, kMaxT));
  std::vector<unsigned> vertices(meshlets.size() * kMaxV);
  std::vector<unsigned char> triangles(meshlets.size() * kMaxT * 3);
  // cone_weight 0.25 trades a little spatial compactness for tighter normal cones (meshoptimizer's advice).
  meshlets.resize(meshopt_buildMeshlets(meshlets.data(), vertices.data(), triangles.data(), mesh.indices.data(),
                                        mesh.indices.size(), pos, nv, sizeof(glm::vec3), kMaxV, kMaxT,
                                        backfaceCone ? 0.25f : 0.0f));
  std::vector<uint32_t> reordered;
  reordered.reserve(mesh.indices.size());
  mesh.clusters.reserve(meshlets.size());
  for (const meshopt_Meshlet& m : meshlets) {
    Cluster c;
    c.firstTriangle = uint32_t(reordered.size() / 3);
    c.triangleCount = m.triangle_count;
    for (size_t k = 0; k < size_t(m.triangle_count) * 3; ++k)
      reordered.push_back(vertices[m.vertex_offset + triangles[m.triangle_offset + k]]);
    const meshopt_Bounds b = meshopt_computeClusterBounds(reordered.data() + size_t(c.firstTriangle) * 3,
                                                          size_t(m.triangle_count) * 3, pos, nv, sizeof(glm::vec3));
    c.center = {b.center[0], b.center[1], b.center[2]};
    c.radius = b.radius;
    c.coneAxis = {b.cone_axis[0], b.cone_axis[1], b.cone_axis[2]};
    c.coneCutoff = backfaceCone ? b.cone_cutoff : 1.0f;
    mesh.clusters.push_back(c);
  }
  // meshoptimizer keeps every triangle, degenerate ones included; a mismatch would lose geometry.
  if (reordered.size() != mesh.indices.size()) throw Error("mesh '" + mesh.name + "': clustering lost triangles");
  mesh.indices = std::move(reordered);
}

bool conesCull(const Material& material) {
  return !(material.flags & (kMaterialAlphaMasked | kMaterialDoubleSided));
}

size_t buildMissingClusters(Scene& scene) {
  std::vector<Mesh*> todo;
  for (Mesh& m : scene.meshes)
    if (m.clusters.empty() && !m.indices.empty()) todo.push_back(&m);
  // Meshes are independent: on all cores, biggest first.
  std::sort(todo.begin(), todo.end(), [](Mesh* a, Mesh* b) { return a->indices.size() > b->indices.size(); });
  parallelFor(todo.size(), 0, [&](size_t i) {
    Mesh& m = *todo[i];
    buildClusters(m, m.material >= scene.materials.size() || conesCull(scene.materials[m.material]));
  });
  return todo.size();
}

}  // namespace rtr
