#version 460
// Visibility pass vertex stage: positions only, plus texcoords where the fragment stage alpha-tests.
#extension GL_GOOGLE_include_directive : require
#include "frame.h"
#include "variants.h"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 2, std430) readonly buffer Instances { GpuInstance instances[]; };
layout(location = 1) flat out uint outFirstId;

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec2 inTexcoord;  // ALPHA_MASK only
layout(location = 0) out vec2 outTexcoord;

void main() {
  if (ALPHA_MASK) outTexcoord = inTexcoord;
  outFirstId = instances[gl_InstanceIndex].info.z;
  gl_Position = frame.viewProj * (instances[gl_InstanceIndex].transform * vec4(inPosition, 1.0));
}
