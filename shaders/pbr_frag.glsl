// The shaded view (mode 1): the brief's Beckmann / Cook-Torrance model for one point light, per fragment,
// in world space. The BRDF itself lives in brdf.h, shared with the CPU reference.
#include "material.glsl"
#include "brdf.h"

layout(location = 0) out vec4 outColor;

// Largest value written to the half-float target (max 65504): a white metal at roughness 0 peaks near
// 8e4 x the light colour; the display clamps at 1 anyway.
const float kMaxRadiance = 60000.0;

void main() {
  Surface s = fetchSurface();
#if ALPHA_MASK
  if (s.alpha < 0.5) discard;
#endif
  vec3 v = normalize(frame.cameraPos.xyz - inWorldPos);
  vec3 toLight = frame.lightPos.xyz - inWorldPos;
  float dist2 = max(dot(toLight, toLight), 1e-12);
  vec3 l = toLight * inversesqrt(dist2);
  vec3 lightColor = frame.lightColor.rgb * (frame.lightColor.w > 0.5 ? 1.0 / dist2 : 1.0);
  vec3 c = shadePbr(shadingNormal(), v, l, lightColor, frame.ambient.rgb, s.baseColor, s.roughness, s.metalness,
                    s.emissive);
  outColor = vec4(min(c, vec3(kMaxRadiance)), 1.0);
}
