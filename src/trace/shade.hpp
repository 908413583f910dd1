#pragma once
// Local shading models: the brief's Blinn-Phong (Task 5) and the GPU renderer's PBR BRDF.
#include <glm/vec3.hpp>

#include "scene/scene.hpp"

namespace rtr::trace {

// Diffuse and specular of one light at one point (no ambient, no emission), Blinn-Phong with Kd, Ks, Ns:
// Lc ⊙ (Kd·max(n·l, 0) + Ks·max(n·h, 0)^Ns), the specular only where n·l > 0. n, v, l: unit vectors.
// No distance falloff, as in the course framework.
glm::vec3 blinnPhongDirect(const Material& m, const glm::vec3& n, const glm::vec3& v, const glm::vec3& l,
                           const glm::vec3& lightColor);
// Ambient of one light: Ka ⊙ Lc. It is all a light gives to a point in its shadow (with Ke).
glm::vec3 blinnPhongAmbient(const Material& m, const glm::vec3& lightColor);

// The GPU renderer's BRDF (shaders/shared/brdf.h): one point light plus constant ambient and emission.
bool pbrAvailable();  // false when this build has no shaders/shared/brdf.h
glm::vec3 shadePbr(const glm::vec3& n, const glm::vec3& v, const glm::vec3& l, const glm::vec3& lightColor,
                   const glm::vec3& ambient, const glm::vec3& baseColor, float roughness, float metalness,
                   const glm::vec3& emissive);

}  // namespace rtr::trace
