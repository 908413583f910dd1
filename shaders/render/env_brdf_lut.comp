#version 460
// The split-sum BRDF table for GGX: texel (x, y) holds (A, B) for n.v = (x + 0.5) / size and roughness
// (y + 0.5) / size, so that the specular of uniform white light is F0 A + B. env_prefilter.h's
// envBrdfLut, the same function the CPU tests evaluate.
#extension GL_GOOGLE_include_directive : require
#include "env_prefilter.h"

layout(local_size_x = ENV_GROUP, local_size_y = ENV_GROUP) in;

layout(set = 0, binding = 0, rg16f) writeonly uniform image2D lut;
layout(push_constant) uniform Push { EnvPush pc; };

void main() {
  const uvec2 id = gl_GlobalInvocationID.xy;
  if (id.x >= pc.size || id.y >= pc.size) return;
  const vec2 ab = envBrdfLut((float(id.x) + 0.5) / float(pc.size), (float(id.y) + 0.5) / float(pc.size), pc.samples);
  imageStore(lut, ivec2(id), vec4(ab, 0.0, 0.0));
}
