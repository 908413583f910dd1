#version 460
// Environment, step 2: the source cube's mip chain, each texel the mean of the four below it (the
// filtered sampling of step 3 reads these levels).
#extension GL_GOOGLE_include_directive : require
#include "env_prefilter.h"

layout(local_size_x = ENV_GROUP, local_size_y = ENV_GROUP) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2DArray src;   // level i
layout(set = 0, binding = 1, rgba32f) writeonly uniform image2DArray dst;  // level i + 1
layout(push_constant) uniform Push { EnvPush pc; };

void main() {
  const uvec3 id = gl_GlobalInvocationID;
  if (id.x >= pc.size || id.y >= pc.size) return;
  const ivec3 s = ivec3(id.xy * 2u, id.z);
  const vec4 c = imageLoad(src, s) + imageLoad(src, s + ivec3(1, 0, 0)) + imageLoad(src, s + ivec3(0, 1, 0)) +
                 imageLoad(src, s + ivec3(1, 1, 0));
  imageStore(dst, ivec3(id), c * 0.25);
}
