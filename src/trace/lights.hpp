#pragma once
// Lights of the classic scenes are geometry (FORMATS.md §2): every object whose material name contains
// "light" (flag kMaterialLight) lights the scene with its Ke. Two triangles make an area light (a
// parallelogram), anything else a point light at the centroid of its vertices.
#include <vector>

#include <glm/vec3.hpp>

#include "scene/scene.hpp"

namespace rtr::trace {

struct Light {
  bool area = false;
  glm::vec3 position{0.0f};  // point light position, or the area light's centre
  glm::vec3 corner{0.0f}, edge1{0.0f}, edge2{0.0f};  // area light: corner + s·edge1 + t·edge2
  glm::vec3 normal{0.0f};    // area light: normal of its first face
  glm::vec3 color{0.0f};     // the material's Ke
  // Where to aim shadow ray `i` of `n` (n = 1: the centre; otherwise a stratified grid on the quad).
  glm::vec3 samplePoint(int i, int n) const;
};

bool isLightMaterial(const Material& m);  // flag set, or "light" in the name
std::vector<Light> extractLights(const Scene& scene);

}  // namespace rtr::trace
