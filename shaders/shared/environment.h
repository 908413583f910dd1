// The environment's geometry, shared by the GPU renderer and the CPU tracer so that both look up the same
// texel for a direction: the equirectangular mapping (with the environment's rotation about +y) and the
// real spherical-harmonic basis of bands 0-2 that diffuse irradiance is stored in (docs/environment.md).
//
// Equirectangular: u runs once around +y (u = 0.5 looks down -z, u = 0.75 down +x), v = 0 is the zenith
// (+y) and v = 1 the nadir. Rows are stored top (v = 0) first, like every image of the project.
#ifndef RTR_SHADERS_SHARED_ENVIRONMENT_H
#define RTR_SHADERS_SHARED_ENVIRONMENT_H

#include "shared.h"
#ifdef __cplusplus
namespace rtr::shader {
using namespace glm;
#endif

RTR_CONST float ENV_PI = 3.14159265358979f;

// Direction (unit, world space) to (u, v) in [0,1]²: u = 0.5 looks down -z (the default view's forward
// direction), u grows towards +x; rotation turns the environment about +y by `rotation` radians.
RTR_FN vec2 envDirToUv(vec3 d, float rotation) {
  float phi = atan(d.x, -d.z) - rotation;  // 0 along -z, +pi/2 along +x
  float u = phi * (0.5f / ENV_PI) + 0.5f;
  u = u - floor(u);
  float v = acos(clamp(d.y, -1.0f, 1.0f)) * (1.0f / ENV_PI);
  return vec2(u, v);
}

// The inverse of envDirToUv.
RTR_FN vec3 envUvToDir(vec2 uv, float rotation) {
  float phi = (uv.x - 0.5f) * (2.0f * ENV_PI) + rotation;
  float theta = uv.y * ENV_PI;
  float s = sin(theta);
  return vec3(s * sin(phi), cos(theta), -s * cos(phi));
}

#ifndef __cplusplus
// The map's radiance at (u, v) (envDirToUv), bilinear as the CPU's Environment::lookup: by hand, so the
// weights keep full float precision (a sampler's are fixed point, 8 bits on many GPUs, and a sun 10^4
// times the sky would be off by tens of units at the pixels its reflection lands on), around the sphere
// in u, clamped in v. GLSL only (needs GL_EXT_samplerless_texture_functions).
vec3 envMapBilinear(texture2D map, vec2 uv) {
  const ivec2 size = textureSize(map, 0);
  const vec2 p = uv * vec2(size) - 0.5;
  const ivec2 i = ivec2(floor(p));
  const vec2 f = p - vec2(i);
  vec3 c[4];
  for (int k = 0; k < 4; ++k) {
    ivec2 q = i + ivec2(k & 1, k >> 1);
    q.x = (q.x + size.x) % size.x;  // u in [0, 1]: q.x >= -1, and GLSL's % of a negative is undefined
    q.y = clamp(q.y, 0, size.y - 1);
    c[k] = texelFetch(map, q, 0).rgb;
  }
  return mix(mix(c[0], c[1], f.x), mix(c[2], c[3], f.x), f.y);
}
#endif

// Real spherical harmonics Y_lm for l = 0..2 at unit direction d, in the order
// (0,0), (1,-1), (1,0), (1,1), (2,-2), (2,-1), (2,0), (2,1), (2,2).
RTR_FN float envSh(int i, vec3 d) {
  if (i == 0) return 0.282094792f;
  if (i == 1) return 0.488602512f * d.y;
  if (i == 2) return 0.488602512f * d.z;
  if (i == 3) return 0.488602512f * d.x;
  if (i == 4) return 1.092548431f * d.x * d.y;
  if (i == 5) return 1.092548431f * d.y * d.z;
  if (i == 6) return 0.315391565f * (3.0f * d.z * d.z - 1.0f);
  if (i == 7) return 1.092548431f * d.x * d.z;
  return 0.546274215f * (d.x * d.x - d.y * d.y);
}

// The clamped-cosine lobe's band factors: irradiance E(n) = sum over i of envShBand(i) L_i Y_i(n), where
// L_i are the radiance's coefficients (pi, 2pi/3, pi/4 for bands 0, 1, 2).
RTR_FN float envShBand(int i) { return i == 0 ? ENV_PI : (i < 4 ? 2.0f * ENV_PI / 3.0f : ENV_PI / 4.0f); }

#ifdef __cplusplus
}  // namespace rtr::shader
#endif
#endif
