#pragma once
// Small scenes built in code (tests, benchmarks, demos): no files needed.
#include <cstdint>

#include <glm/vec3.hpp>

#include "scene/scene.hpp"

namespace rtr::trace {

// A closed UV sphere: `rings` bands of latitude, `segments` of longitude, poles as triangle fans,
// every edge shared by exactly two triangles through shared vertex indices. Smooth normals.
Mesh uvSphere(glm::vec3 centre, float radius, uint32_t rings, uint32_t segments, uint32_t material = 0);
// A parallelogram corner + s·e1 + t·e2 as two triangles split along the corner→opposite diagonal.
Mesh quad(glm::vec3 corner, glm::vec3 e1, glm::vec3 e2, uint32_t material = 0);
// An axis-aligned box of 12 triangles, normals pointing out (or in, when `inward`).
Mesh box(glm::vec3 lo, glm::vec3 hi, uint32_t material = 0, bool inward = false);

// Adds a material and returns its index.
uint32_t addMaterial(Scene& scene, Material m);
void addMesh(Scene& scene, Mesh mesh);  // computes the mesh bounds

}  // namespace rtr::trace
