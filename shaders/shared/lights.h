// The light model both renderers evaluate: point lights with a colour × intensity and an optional
// inverse-square falloff. The CPU tracer's area lights (two-triangle `*light*` quads) reach the GPU as
// a point light at the quad's centre, which is exactly what the tracer does with one shadow sample per
// area light (its default); with more samples only the tracer's shadows soften (docs/lights.md).
#ifndef RTR_SHADERS_SHARED_LIGHTS_H
#define RTR_SHADERS_SHARED_LIGHTS_H

#include "shared.h"

#ifdef __cplusplus
namespace rtr::shader {
using namespace glm;
#endif

// Lights in one frame; the scene loader keeps at most this many (scene/lights.hpp).
#define MAX_LIGHTS 8

struct GpuLight {
  vec4 position;  // xyz world position; w: 1 = inverse-square falloff, 0 = none
  vec4 color;     // rgb colour x intensity
};

// Unit direction from p towards the light and the radiance that arrives at p.
struct LightSample {
  vec3 l;
  vec3 radiance;
};

RTR_FN LightSample lightSample(vec3 lightPos, vec3 lightColor, bool falloff, vec3 p) {
  vec3 toLight = lightPos - p;
  float dist2 = max(dot(toLight, toLight), 1e-12f);
  LightSample s;
  s.l = toLight * (1.0f / sqrt(dist2));
  s.radiance = falloff ? lightColor * (1.0f / dist2) : lightColor;
  return s;
}

#ifdef __cplusplus
}  // namespace rtr::shader
#endif
#endif
