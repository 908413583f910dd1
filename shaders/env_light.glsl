// Light from an environment for the shaded view's HAS_ENV variants (forward, visibility shading, the
// forward path's backdrop): the split sum of env_prefilter.h from the maps of render/environment_maps.hpp.
// Needs `frame` (FrameUniforms) declared before it. Set 0, bindings 20-24, in every pipeline that reads it.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "environment.h"
#include "env_prefilter.h"

layout(set = 0, binding = 20) uniform samplerCube envSpecular;  // roughness (level / last level) per mip
layout(set = 0, binding = 21) uniform sampler2D envLut;         // (A, B, C): Beckmann's rows, then GGX's
layout(set = 0, binding = 22, std430) readonly buffer EnvSh { vec4 envShCoeffs[9]; };  // radiance, rgb
layout(set = 0, binding = 23) uniform samplerCube envSource;    // the environment itself (the sharp backdrop)
layout(set = 0, binding = 24) uniform texture2D envMap;         // the equirectangular map (the mirror)

// Diffuse irradiance at unit normal n from the radiance's SH coefficients; the band limit can ring below
// zero next to a sun, so it is clamped.
vec3 envIrradiance(vec3 n) {
  vec3 e = vec3(0.0);
  for (int i = 0; i < 9; ++i) e += envShBand(i) * envShCoeffs[i].rgb * envSh(i, n);
  return max(e, vec3(0.0));
}

// The prefiltered radiance along r at the specular cube's level `lod` (roughness x its last level). The
// sharpest level (roughness 0) is the map itself, read along r as the CPU reads it, not the cube's level 0:
// a sun in one texel of the map, resampled into a cube and read from it again, lands on other pixels with
// other values. Between it and level 1, a blend as the cube's own levels are.
vec3 envPrefiltered(vec3 r, float lod) {
  if (lod < 1.0) return mix(envMapBilinear(envMap, envDirToUv(r, frame.environment.w)), textureLod(envSpecular, r, 1.0).rgb, lod);
  return textureLod(envSpecular, r, lod).rgb;
}

// What the environment adds to a surface (before any cap), its diffuse and specular terms apart (the debug
// views show each): brdf.h's rules for a normal below the view (diffuse kept, no specular) and a zero
// normal (nothing); `occlusion` (glTF's texture, 1 elsewhere) scales both terms, as glTF viewers do for
// light from the environment.
void envLightTerms(int brdf, vec3 n, vec3 v, vec3 baseColor, float roughness, float metalness, float occlusion,
                   out vec3 diffuse, out vec3 specular) {
  diffuse = specular = vec3(0.0);
  const vec3 nn = brdfSafeNormal(n);
  if (dot(nn, nn) == 0.0) return;
  const float nv = dot(nn, v), rough = clamp(roughness, 0.0, 1.0);
  const vec3 abc = textureLod(envLut, envLutUv(brdf, clamp(nv, 0.0, 1.0), rough, frame.environment.z), 0.0).rgb;
  const vec3 pre = nv > 0.0 ? envPrefiltered(reflect(-v, nn), rough * frame.environment.x) : vec3(0.0);
  // envSplitSum is linear in the irradiance and the prefiltered radiance: each term alone.
  diffuse = envSplitSum(brdf, envIrradiance(nn), vec3(0.0), abc, baseColor, metalness) * occlusion;
  specular = envSplitSum(brdf, vec3(0.0), pre, abc, baseColor, metalness) * occlusion;
}

vec3 envLight(int brdf, vec3 n, vec3 v, vec3 baseColor, float roughness, float metalness, float occlusion) {
  vec3 diffuse, specular;
  envLightTerms(brdf, n, v, baseColor, roughness, metalness, occlusion, diffuse, specular);
  return diffuse + specular;
}

// The backdrop towards world direction d (any length), as frame.environment.y says; or the colour.
vec3 envBackdrop(vec3 d) {
  const float blur = frame.environment.y;
  if (blur < 0.0) return frame.background.rgb;
  if (blur == 0.0) return textureLod(envSource, d, 0.0).rgb;
  return textureLod(envSpecular, d, blur * frame.environment.x).rgb;
}
