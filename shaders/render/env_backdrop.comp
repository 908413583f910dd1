#version 460
// The forward path's backdrop with an environment: every pixel the scene pass left at its clear value
// (alpha 0; the shaded view writes alpha 1) gets the environment seen along its ray, as the visibility
// path's shading pass does for its empty pixels (env_light.glsl's envBackdrop).
#extension GL_GOOGLE_include_directive : require
#include "frame.h"

layout(local_size_x = VIS_GROUP_X, local_size_y = VIS_GROUP_Y) in;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 8, rgba16f) uniform image2D sceneColor;
#include "env_light.glsl"

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, imageSize(sceneColor))) || imageLoad(sceneColor, p).a != 0.0) return;
  const vec3 dir = frame.rayDir.xyz + (vec2(p) + 0.5).x * frame.rayDx.xyz + (vec2(p) + 0.5).y * frame.rayDy.xyz;
  imageStore(sceneColor, p, vec4(min(envBackdrop(dir), vec3(60000.0)), 1.0));
}
