#pragma once
// Local shading models: the brief's Blinn-Phong (Task 5) and the GPU renderer's PBR BRDF, per light.
#include <glm/vec3.hpp>

#include "lights.h"  // shaders/shared: the light model both renderers evaluate (lightSample)
#include "scene/scene.hpp"

namespace rtr::trace {

// Diffuse and specular of one light at one point (no ambient, no emission), Blinn-Phong with kd (Kd, or Kd
// times the base-colour texture of a model from elsewhere), Ks, Ns:
// Lc ⊙ (Kd·max(n·l, 0) + Ks·max(n·h, 0)^Ns), the specular only where n·l > 0. n, v, l: unit vectors.
// Lc is the radiance arriving (lightSample: the course's lights have no falloff unless asked).
glm::vec3 blinnPhongDirect(const Material& m, const glm::vec3& kd, const glm::vec3& n, const glm::vec3& v, const glm::vec3& l,
                           const glm::vec3& lightColor);
// Ambient of one light: Ka ⊙ Lc. It is all a light gives to a point in its shadow (with Ke).
glm::vec3 blinnPhongAmbient(const Material& m, const glm::vec3& lightColor);

// The GPU renderer's BRDF for one light (shaders/shared/brdf.h's pbrDirect, compiled here as C++); brdf:
// BRDF_BECKMANN or BRDF_GGX.
glm::vec3 pbrDirect(int brdf, const glm::vec3& n, const glm::vec3& v, const glm::vec3& l, const glm::vec3& lightColor,
                    const glm::vec3& baseColor, float roughness, float metalness);

}  // namespace rtr::trace
