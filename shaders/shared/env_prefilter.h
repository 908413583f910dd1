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

// A GGX half vector (alpha = roughness²) drawn in proportion to D(h) (h.n), in the frame whose z is n; its
// density per solid angle of h is D · n.h, with brdf.h's brdfGgxD.
RTR_FN vec3 envGgxHalf(vec2 u, float alpha) {
  float phi = 2.0f * BRDF_PI * u.x;
  float cos2 = (1.0f - u.y) / (1.0f + (alpha * alpha - 1.0f) * u.y);
  float c = sqrt(cos2), s = sqrt(max(1.0f - cos2, 0.0f));
  return vec3(s * cos(phi), s * sin(phi), c);
}

// Any unit vector t perpendicular to n, and b = n x t: the frame envGgxHalf's vectors are given in.
RTR_FN vec3 envTangent(vec3 n) {
  vec3 up = abs(n.z) < 0.999f ? vec3(0.0f, 0.0f, 1.0f) : vec3(1.0f, 0.0f, 0.0f);
  return normalize(cross(up, n));
}

// One row of the split-sum table: for view angle n.v and roughness, the scale A and bias B such that the
// GGX specular's hemispherical integral under uniform white light is F0 A + B (Schlick Fresnel), by
// `samples` half vectors drawn from D. Evaluated the same way on the GPU (env_brdf_lut.comp) and the CPU.
RTR_FN vec2 envBrdfLut(float nv, float roughness, uint samples) {
  float alpha = max(roughness * roughness, BRDF_ALPHA_MIN);
  nv = max(nv, 1e-4f);
  vec3 v = vec3(sqrt(max(1.0f - nv * nv, 0.0f)), 0.0f, nv);
  float a = 0.0f, b = 0.0f;
  for (uint i = 0u; i < samples; ++i) {
    vec3 h = envGgxHalf(envHammersley(i, samples), alpha);
    float vh = dot(v, h);
    vec3 l = 2.0f * vh * h - v;
    float nl = l.z, nh = h.z;
    if (nl > 0.0f && vh > 0.0f) {
      // f cos / pdf with pdf(l) = D n.h / (4 v.h):  F · V · 4 · nl · vh / nh.
      float w = brdfGgxVisibility(nv, nl, alpha) * 4.0f * nl * vh / nh;
      float fc = pow(1.0f - vh, 5.0f);
      a += (1.0f - fc) * w;
      b += fc * w;
    }
  }
  return vec2(a, b) / float(samples);
}

// Push constants of the prefiltering passes.
struct EnvPush {
  uint size;        // output face size (texels) of the level written
  uint samples;     // specular and table: sample points per texel
  float roughness;  // specular: of the level written
  float srcTexelSolidAngle;  // specular: of a level-0 texel of the source cube (filtered sampling)
  float rotation;   // to the cube: the environment's rotation about +y, radians
  uint srcWidth;    // to the cube: the equirectangular map's size
  uint srcHeight;
  uint srcLevels;   // specular: mip levels of the source cube
  uint level;       // spherical harmonics: the source level read
  uint pad0, pad1, pad2;
};
#define ENV_GROUP 8

#ifdef __cplusplus
}  // namespace rtr::shader
#endif
#endif
