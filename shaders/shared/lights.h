// The light model both renderers evaluate: point, spot and directional lights (glTF KHR_lights_punctual),
// a colour × intensity, an optional inverse-square falloff and an optional range. The CPU tracer's area
// lights (two-triangle `*light*` quads) reach the GPU as a point light at the quad's centre, which is
// exactly what the tracer does with one shadow sample per area light (its default); with more samples only
// the tracer's shadows soften (docs/lights.md).
#ifndef RTR_SHADERS_SHARED_LIGHTS_H
#define RTR_SHADERS_SHARED_LIGHTS_H

#include "shared.h"

#ifdef __cplusplus
namespace rtr::shader {
using namespace glm;
#endif

// Lights in one frame; the scene loader keeps at most this many (scene/lights.hpp).
#define MAX_LIGHTS 8

// GpuLight::color.w: the number of scene/scene.hpp's Light::Kind (static_asserted where lights are
// packed). Every other kind is a point light here: a point light, an area light at its sample point, the
// headlight at the camera.
#define LIGHT_POINT 0
#define LIGHT_SPOT 3
#define LIGHT_DIRECTIONAL 4

// What LightSample::distance holds for a directional light (shadow rays go to infinity).
RTR_CONST float LIGHT_FAR = 3.0e38f;

struct GpuLight {
  vec4 position;   // xyz position (unused by a directional light); w: 1 = inverse-square falloff, 0 = none
  vec4 color;      // rgb colour x intensity; w: LIGHT_SPOT, LIGHT_DIRECTIONAL, else a point light
  vec4 direction;  // xyz unit direction the light travels (spot, directional); w: range, 0 = unbounded
  vec4 cone;       // spot: x cos(inner cone angle), y cos(outer cone angle); zw unused
};

// Unit direction from p towards the light, the radiance that arrives at p and the distance to the light
// (LIGHT_FAR for a directional light).
struct LightSample {
  vec3 l;
  vec3 radiance;
  float distance;
};

// glTF's smooth spot edge: 1 inside the inner cone, 0 outside the outer, and between them the square of a
// linear ramp in the cosine of the angle to the axis. inner <= outer (a hard edge) gives a step at outer.
RTR_FN float lightSpotFactor(float cosAngle, float innerCos, float outerCos) {
  float scale = 1.0f / max(innerCos - outerCos, 1e-4f);
  float t = clamp((cosAngle - outerCos) * scale, 0.0f, 1.0f);
  return t * t;
}

// glTF's range window: (1 - (d/range)^4) clamped to [0, 1], so the light ends smoothly at `range`.
RTR_FN float lightRangeFactor(float dist, float range) {
  if (range <= 0.0f) return 1.0f;
  float x = dist / range;
  float x2 = x * x;
  return clamp(1.0f - x2 * x2, 0.0f, 1.0f);
}

RTR_FN LightSample lightSample(GpuLight light, vec3 p) {
  LightSample s;
  vec3 color = vec3(light.color.x, light.color.y, light.color.z);
  vec3 dir = vec3(light.direction.x, light.direction.y, light.direction.z);
  if (light.color.w > 3.5f) {  // directional: parallel rays, the same radiance everywhere
    s.l = -dir;
    s.radiance = color;
    s.distance = LIGHT_FAR;
    return s;
  }
  vec3 toLight = vec3(light.position.x, light.position.y, light.position.z) - p;
  float dist2 = max(dot(toLight, toLight), 1e-12f);
  s.distance = sqrt(dist2);
  s.l = toLight * (1.0f / s.distance);
  float k = light.position.w > 0.5f ? 1.0f / dist2 : 1.0f;
  k *= lightRangeFactor(s.distance, light.direction.w);
  if (light.color.w > 2.5f) k *= lightSpotFactor(dot(-s.l, dir), light.cone.x, light.cone.y);
  s.radiance = color * k;
  return s;
}

// A point light without range (the form the renderer's shaders used before spot and directional lights).
RTR_FN LightSample lightSample(vec3 lightPos, vec3 lightColor, bool falloff, vec3 p) {
  GpuLight light;
  light.position = vec4(lightPos, falloff ? 1.0f : 0.0f);
  light.color = vec4(lightColor, float(LIGHT_POINT));
  light.direction = vec4(0.0f);
  light.cone = vec4(0.0f);
  return lightSample(light, p);
}

#ifdef __cplusplus
static_assert(sizeof(GpuLight) == 4 * 16 && alignof(GpuLight) <= 16);

// A GpuLight from a light's fields (scene/scene.hpp's Light: kind = unsigned(Light::Kind)), for both
// renderers; `position` is where a point light is (an area light's sample point, the headlight's camera).
inline GpuLight makeGpuLight(unsigned kind, vec3 position, vec3 color, bool falloff, vec3 direction, float innerConeCos,
                             float outerConeCos, float range) {
  return {vec4(position, falloff ? 1.0f : 0.0f), vec4(color, float(kind)), vec4(direction, range),
          vec4(innerConeCos, outerConeCos, 0.0f, 0.0f)};
}
}  // namespace rtr::shader
#endif
#endif
