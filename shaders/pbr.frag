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

// BLEND (the transparency pass, render/transparency.cpp): "over" blending by the surface's alpha. Where the
// compute rasteriser drew the opaque surfaces, their depth is the high half of its per-pixel word
// (draw.opaqueWidth its row length); the hardware paths test against the depth attachment instead (0).
layout(set = 0, binding = 7, std430) readonly buffer OpaqueIds { uvec2 opaqueIds[]; };  // BLEND only
bool behindOpaque() {
  if (draw.opaqueWidth == 0u) return false;
  const uvec2 p = uvec2(gl_FragCoord.xy);
  return gl_FragCoord.z >= uintBitsToFloat(opaqueIds[p.y * draw.opaqueWidth + p.x].y);  // empty: NaN, false
}
float outAlpha(Surface s) { return BLEND ? clamp(s.alpha, 0.0, 1.0) : 1.0; }

void main() {
  if (BLEND) {
    if (behindOpaque()) discard;
  }
  Surface s = fetchSurface();
  if (ALPHA_MASK) {  // a branch on the constant alone, which specialization folds
    if (cutOut(s)) discard;
  }
  if (unlit()) {
    outColor = vec4(min(s.baseColor, vec3(kMaxRadiance)), outAlpha(s));
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
  outColor = vec4(min(c, vec3(kMaxRadiance)), outAlpha(s));
}
