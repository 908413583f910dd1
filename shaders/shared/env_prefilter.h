// Prefiltering an environment for the split-sum approximation (docs/environment.md), shared by the GPU's
// compute passes (shaders/render/env_*.comp) and their CPU references in the tests: cube-face directions,
// the low-discrepancy sample points, GGX half-vector sampling and the split-sum BRDF table's integrand.
#ifndef RTR_SHADERS_SHARED_ENV_PREFILTER_H
#define RTR_SHADERS_SHARED_ENV_PREFILTER_H

#include "brdf.h"
#ifdef __cplusplus
namespace rtr::shader {
using namespace glm;
#endif

// The direction through (s, t) in [-1,1]² of cube face f, in Vulkan's order +X, -X, +Y, -Y, +Z, -Z and
// orientation (the texel a cube sampler reads for that direction).
RTR_FN vec3 envCubeDir(uint f, vec2 st) {
  float s = st.x, t = st.y;
  vec3 d;
  if (f == 0u) d = vec3(1.0f, -t, -s);
  else if (f == 1u) d = vec3(-1.0f, -t, s);
  else if (f == 2u) d = vec3(s, 1.0f, t);
  else if (f == 3u) d = vec3(s, -1.0f, -t);
  else if (f == 4u) d = vec3(s, -t, 1.0f);
  else d = vec3(-s, -t, -1.0f);
  return normalize(d);
}

// Solid angle of texel (x, y) of a face `size` texels wide.
RTR_FN float envCubeTexelSolidAngle(uint x, uint y, uint size) {
  float inv = 1.0f / float(size);
  float s0 = 2.0f * float(x) * inv - 1.0f, s1 = s0 + 2.0f * inv;
  float t0 = 2.0f * float(y) * inv - 1.0f, t1 = t0 + 2.0f * inv;
  // The area element's integral: atan(st / sqrt(s² + t² + 1)) at the four corners.
  return atan(s0 * t0, sqrt(s0 * s0 + t0 * t0 + 1.0f)) - atan(s0 * t1, sqrt(s0 * s0 + t1 * t1 + 1.0f)) -
         atan(s1 * t0, sqrt(s1 * s1 + t0 * t0 + 1.0f)) + atan(s1 * t1, sqrt(s1 * s1 + t1 * t1 + 1.0f));
}

// Point i of n of the Hammersley set: (i/n, bits of i reversed).
RTR_FN vec2 envHammersley(uint i, uint n) {
  uint b = i;
  b = (b << 16u) | (b >> 16u);
  b = ((b & 0x55555555u) << 1u) | ((b & 0xAAAAAAAAu) >> 1u);
  b = ((b & 0x33333333u) << 2u) | ((b & 0xCCCCCCCCu) >> 2u);
  b = ((b & 0x0F0F0F0Fu) << 4u) | ((b & 0xF0F0F0F0u) >> 4u);
  b = ((b & 0x00FF00FFu) << 8u) | ((b & 0xFF00FF00u) >> 8u);
  return vec2(float(i) / float(n), float(b) * 2.3283064365386963e-10f);
}

// A GGX half vector about +z from a Hammersley pair (alpha = roughness²), density D · n.h per solid
// angle of h: brdf.h's sampling, with the pair's radical inverse picking the angle from n.
RTR_FN vec3 envGgxHalf(vec2 u, float alpha) { return brdfSampleHalfLocal(BRDF_GGX, vec2(u.y, u.x), alpha); }

// Any unit vector t perpendicular to n, and b = n x t: the frame envGgxHalf's vectors are given in.
RTR_FN vec3 envTangent(vec3 n) {
  vec3 up = abs(n.z) < 0.999f ? vec3(0.0f, 0.0f, 1.0f) : vec3(1.0f, 0.0f, 0.0f);
  return normalize(cross(up, n));
}

// One texel of the split-sum table for BRDF `brdf` (brdf.h's BRDF_BECKMANN or BRDF_GGX): for view angle
// n.v and roughness, (A, B, C) such that under uniform white light
//   * the specular's hemispherical integral is F0 A + B (Schlick Fresnel; A, B by `samples` half vectors
//     drawn from the BRDF's own D, f cos / pdf = F V 4 n.l v.h / n.h);
//   * the diffuse's is c (1 - M)(1 - F0d)(1 - C), with C the cosine-weighted mean of (1 - v.h)^5 over the
//     hemisphere (the Fresnel weight both diffuse terms of brdf.h carry; F0d = 0.04 for GGX, F0 for
//     Beckmann), by `samples` cosine-distributed light directions. C depends on n.v only.
// Evaluated the same way on the GPU (env_brdf_lut.comp) and the CPU.
RTR_FN vec3 envBrdfLut(int brdf, float nv, float roughness, uint samples) {
  float alpha = max(roughness * roughness, BRDF_ALPHA_MIN);
  nv = max(nv, 1e-4f);
  vec3 v = vec3(sqrt(max(1.0f - nv * nv, 0.0f)), 0.0f, nv);
  float a = 0.0f, b = 0.0f, cw = 0.0f;
  for (uint i = 0u; i < samples; ++i) {
    vec2 u = envHammersley(i, samples);
    vec3 h = brdfSampleHalfLocal(brdf, vec2(u.y, u.x), alpha);
    float vh = dot(v, h);
    vec3 l = 2.0f * vh * h - v;
    float nl = l.z, nh = h.z;
    if (nl > 0.0f && vh > 0.0f) {
      vec3 H = v + l;
      float V = brdf == BRDF_GGX ? brdfGgxVisibility(nv, nl, alpha) : brdfVisibility(nv, nl, H.z, dot(H, H));
      float w = V * 4.0f * nl * vh / nh;
      float fc = pow(1.0f - vh, 5.0f);
      a += (1.0f - fc) * w;
      b += fc * w;
    }
    // Cosine-distributed l: the diffuse's Fresnel weight.
    float r = sqrt(u.y), phi = 2.0f * BRDF_PI * u.x;
    vec3 ld = vec3(r * cos(phi), r * sin(phi), sqrt(max(1.0f - u.y, 0.0f)));
    vec3 hd = v + ld;
    float vhd = 0.5f * sqrt(dot(hd, hd));  // v.h for unit v, l
    cw += pow(1.0f - vhd, 5.0f);
  }
  return vec3(a, b, cw) / float(samples);
}

// Where the shading passes read the table: block `brdf` of rows (the table is `size` wide, 2 size high:
// BRDF_BECKMANN's rows, then BRDF_GGX's), clamped to texel centres so bilinear filtering never mixes them.
RTR_FN vec2 envLutUv(int brdf, float nv, float roughness, float size) {
  float lo = 0.5f / size, hi = 1.0f - 0.5f / size;
  vec2 t = clamp(vec2(nv, roughness), vec2(lo), vec2(hi));
  return vec2(t.x, (t.y + float(brdf)) * 0.5f);
}

// Multiple-scattering energy compensation (docs/environment.md), for BRDF_GGX only: a single-scattering
// microfacet BRDF loses the light that would leave after more than one bounce, 1 - E of white light
// (E = A + B, the white metal's albedo at n.v); it comes back mostly along the single-scattering lobe,
// tinted by F0 once more per bounce, so the specular is scaled by 1 + F0 (1 / E - 1) (a white metal
// reflects all the light). Beckmann, the brief's model, stays single scattering: 1.
RTR_FN vec3 envMultiScatter(int brdf, vec3 F0, float E) {
  if (brdf != BRDF_GGX) return vec3(1.0f);
  return vec3(1.0f) + F0 * (1.0f / max(E, 1e-3f) - 1.0f);
}

// The split sum (docs/environment.md): what the environment adds to a surface, from the diffuse
// irradiance E(n) (spherical harmonics), the specular cube's radiance along the mirror direction at the
// surface's roughness, and the table's (A, B, C) at (n.v, roughness) for the same BRDF as brdf.h's:
//   diffuse  = E/pi c (1 - M)(1 - F0d)(1 - C)   (exact for uniform light: brdf.h's diffuse integrated)
//   specular = prefiltered (F0 A + B) ms         (F0 = mix(0.04, c, M); ms = envMultiScatter(F0, A + B))
// For uniform radiance 1 (E = pi, prefiltered = 1) this is the BRDF's directional albedo (with the
// compensation for GGX: 1 for a white metal).
RTR_FN vec3 envSplitSum(int brdf, vec3 irradiance, vec3 prefiltered, vec3 abc, vec3 baseColor, float metalness) {
  vec3 c = clamp(baseColor, vec3(0.0f), vec3(1.0f));
  float m = clamp(metalness, 0.0f, 1.0f);
  vec3 F0 = mix(vec3(0.04f), c, m);
  vec3 F0d = brdf == BRDF_GGX ? vec3(0.04f) : F0;
  vec3 diffuse = irradiance * (1.0f / BRDF_PI) * c * (1.0f - m) * (vec3(1.0f) - F0d) * (1.0f - abc.z);
  return diffuse + prefiltered * (F0 * abc.x + vec3(abc.y)) * envMultiScatter(brdf, F0, abc.x + abc.y);
}

// Push constants of the prefiltering passes.
struct EnvPush {
  uint size;        // output face size (texels) of the level written
  uint samples;     // specular and table: sample points per texel
  float roughness;  // specular: of the level written
  float srcTexelSolidAngle;  // specular: of a level-0 texel of the source cube (filtered sampling)
  float rotation;   // to the cube: the environment's rotation about +y, radians
  uint srcLevels;   // specular: mip levels of the source cube
  uint level;       // spherical harmonics and the specular sum: the source level read
  uint srcSize;     // specular sum: that level's face size
  float nearAngle;  // specular sum: how far from a texel's direction the lobe is summed at that level (radians)
};
#define ENV_GROUP 8
#define ENV_SUM_SLICES 4  // env_specular_sum.comp: threads per output texel

#ifdef __cplusplus
}  // namespace rtr::shader
#endif
#endif
