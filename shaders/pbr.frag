#version 460
#extension GL_GOOGLE_include_directive : require
// The shaded view (mode 1): the material's BRDF (brdf.h, shared with the CPU reference) summed over the
// frame's lights, per fragment, in world space, plus the environment's split sum in the HAS_ENV variant.
#include "material.glsl"
#include "brdf.h"
#include "env_light.glsl"

layout(location = 0) out vec4 outColor;

// Largest value written to the half-float target (max 65504): a white metal at roughness 0 peaks near
// 8e4 x the light colour; the display clamps at 1 anyway.
const float kMaxRadiance = 60000.0;

void main() {
  Surface s = fetchSurface();
  if (ALPHA_MASK) {  // a branch on the constant alone, which specialization folds
    if (cutOut(s)) discard;
  }
  if (unlit()) {
    outColor = vec4(min(s.baseColor, vec3(kMaxRadiance)), 1.0);
    return;
  }
  vec3 v = normalize(frame.cameraPos.xyz - inWorldPos);
  vec3 n = shadingNormal(s);
  const int brdf = brdfOf();
  vec3 c = frame.ambient.rgb * clamp(s.baseColor, vec3(0.0), vec3(1.0)) * s.occlusion + s.emissive;
  for (uint i = 0u; i < frame.lightCount.x; ++i) {
    LightSample ls = lightSample(frame.lights[i], inWorldPos);  // point, spot or directional (lights.h)
    c += pbrDirect(brdf, n, v, ls.l, ls.radiance, s.baseColor, s.roughness, s.metalness);
  }
  if (HAS_ENV) c += envLight(brdf, n, v, s.baseColor, s.roughness, s.metalness, s.occlusion);
  outColor = vec4(min(c, vec3(kMaxRadiance)), 1.0);
}
