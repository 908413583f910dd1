#version 460
// Environment, step 4: radiance projected onto spherical harmonics of bands 0-2 (9 coefficients per
// channel) from one level of the source cube, each texel weighted by its exact solid angle. One
// workgroup: the level is small (at most 64² a face), and a fixed order of sums gives the same result
// every run.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "environment.h"
#include "env_prefilter.h"

#define SH_THREADS 256
layout(local_size_x = SH_THREADS) in;

layout(set = 0, binding = 0) uniform texture2DArray src;  // the source cube's faces
layout(set = 0, binding = 1) writeonly buffer Sh { vec4 coeffs[9]; };
layout(push_constant) uniform Push { EnvPush pc; };

shared vec3 partial[SH_THREADS];

void main() {
  const uint tid = gl_LocalInvocationID.x;
  vec3 acc[9];
  for (int k = 0; k < 9; ++k) acc[k] = vec3(0.0);
  const uint perFace = pc.size * pc.size;
  for (uint i = tid; i < 6u * perFace; i += SH_THREADS) {
    const uint f = i / perFace, x = i % pc.size, y = (i % perFace) / pc.size;
    const vec3 d = envCubeDir(f, (vec2(x, y) + 0.5) / float(pc.size) * 2.0 - 1.0);
    const vec3 l = texelFetch(src, ivec3(x, y, f), int(pc.level)).rgb * envCubeTexelSolidAngle(x, y, pc.size);
    for (int k = 0; k < 9; ++k) acc[k] += l * envSh(k, d);
  }
  for (int k = 0; k < 9; ++k) {
    partial[tid] = acc[k];
    barrier();
    for (uint s = SH_THREADS / 2u; s > 0u; s >>= 1u) {
      if (tid < s) partial[tid] += partial[tid + s];
      barrier();
    }
    if (tid == 0u) coeffs[k] = vec4(partial[0], 0.0);
    barrier();
  }
}
