// Scene vertex stage. Each input is its own tightly packed stream; the texcoord stream exists only in
// the textured variant (a scene without texcoords binds none).
#extension GL_GOOGLE_include_directive : require
#include "frame.h"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 2, std430) readonly buffer Instances { GpuInstance instances[]; };

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
#if HAS_TEXCOORDS
layout(location = 2) in vec2 inTexcoord;
layout(location = 2) out vec2 outTexcoord;
#endif
layout(location = 0) out vec3 outWorldPos;
layout(location = 1) out vec3 outNormal;

void main() {
  const GpuInstance inst = instances[gl_InstanceIndex];  // includes the draw's firstInstance
  const vec4 world = inst.transform * vec4(inPosition, 1.0);
  outWorldPos = world.xyz;
  outNormal = mat3(inst.normalX.xyz, inst.normalY.xyz, inst.normalZ.xyz) * inNormal;
#if HAS_TEXCOORDS
  outTexcoord = inTexcoord;
#endif
  gl_Position = frame.viewProj * world;
}
