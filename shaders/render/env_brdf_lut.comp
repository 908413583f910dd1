#version 460
// The split-sum BRDF table for both BRDFs: rows 0..size-1 Beckmann, size..2 size-1 GGX; texel (x, y) holds
// (A, B, C) for n.v = (x + 0.5) / size and roughness (y mod size + 0.5) / size, so that the specular of
// uniform white light is F0 A + B and the diffuse's Fresnel weight is 1 - C. env_prefilter.h's
// envBrdfLut, the same function the CPU tests evaluate.
#extension GL_GOOGLE_include_directive : require
#include "env_prefilter.h"

layout(local_size_x = ENV_GROUP, local_size_y = ENV_GROUP) in;

layout(set = 0, binding = 0, rgba16f) writeonly uniform image2D lut;
layout(push_constant) uniform Push { EnvPush pc; };

void main() {
  const uvec2 id = gl_GlobalInvocationID.xy;
  if (id.x >= pc.size || id.y >= 2u * pc.size) return;
  const int brdf = id.y < pc.size ? BRDF_BECKMANN : BRDF_GGX;
  const uint row = id.y % pc.size;
  const vec3 abc = envBrdfLut(brdf, (float(id.x) + 0.5) / float(pc.size), (float(row) + 0.5) / float(pc.size), pc.samples);
  imageStore(lut, ivec2(id), vec4(abc, 0.0));
}
