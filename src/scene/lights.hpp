#pragma once
// Which lights light a scene, one rule for every tool (docs/lights.md):
// 1. --light on the command line replaces the scene's lights with one point light;
// 2. else the lights stored with the scene (.rtrscene; the course format's standard light);
// 3. else its light geometry (the course's convention, docs/formats.md): every object whose material name
//    contains "light" lights the scene with its Ke (its Kd when it has no Ke); two triangles make an area
//    light (a parallelogram), anything else a point
//    light at the centroid of its vertices;
// 4. else, unless switched off, a headlight at the camera, announced once.
// At most kMaxLights are kept (the GPU's frame uniforms hold that many); the rest are dropped with a note.
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "scene/scene.hpp"

namespace rtr {

constexpr size_t kMaxLights = 8;  // MAX_LIGHTS in shaders/shared/lights.h

// The course's standard light of the Vulkan part (docs/formats.md).
Light briefLight();

bool isLightMaterial(const Material& m);  // flag set, or "light" in the name
std::vector<Light> lightsFromGeometry(const Scene& scene);

struct LightOptions {
  std::optional<glm::vec3> position;  // --light x,y,z: one point light instead of the scene's
  glm::vec3 color{1.0f};              // --light-color, for that light
  bool falloff = false;               // --falloff: inverse-square falloff on every light but a headlight
  bool defaultLight = true;           // false: --no-default-light (the brief's strict behaviour)
  glm::vec3 ambient{0.02f};           // --ambient r,g,b: constant ambient colour
};

struct LightRig {
  std::vector<Light> lights;
  glm::vec3 ambient{0.02f};
  std::string note;  // what was chosen when it is not simply the scene's own lights (print it once)
};

LightRig resolveLights(const Scene& scene, const LightOptions& options = {});
// Whether the scene brings lights of its own (stored or as geometry).
bool hasOwnLights(const Scene& scene);

}  // namespace rtr
