#version 460
// Environment, step 1: the equirectangular map (linear radiance) onto level 0 of a cube, each texel the
// mean of 4x4 bilinear samples over its area so that a small bright source (the sun in one texel of the
// map) keeps its energy. docs/environment.md.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "environment.h"
#include "env_prefilter.h"

layout(local_size_x = ENV_GROUP, local_size_y = ENV_GROUP) in;

layout(set = 0, binding = 0) uniform texture2D equirect;
layout(set = 0, binding = 1, rgba32f) writeonly uniform image2DArray cube;
layout(push_constant) uniform Push { EnvPush pc; };

void main() {
  const uvec3 id = gl_GlobalInvocationID;
  if (id.x >= pc.size || id.y >= pc.size) return;
  vec3 sum = vec3(0.0);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const vec2 st = (vec2(id.xy) + (vec2(i, j) + 0.5) / 4.0) / float(pc.size) * 2.0 - 1.0;
      sum += envMapBilinear(equirect, envDirToUv(envCubeDir(id.z, st), pc.rotation));
    }
  imageStore(cube, ivec3(id), vec4(sum / 16.0, 1.0));
}
