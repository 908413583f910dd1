#version 460
// Scene vertex stage. Each input is its own tightly packed stream; the texcoord stream exists only in
// the textured variant (a scene without texcoords binds none).
#extension GL_GOOGLE_include_directive : require
#include "frame.h"
#include "variants.h"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 2, std430) readonly buffer Instances { GpuInstance instances[]; };
// glTF's streams, by gl_VertexIndex where the draw has them (GpuDraw flags); OBJ scenes bind any buffer.
layout(set = 0, binding = 3, std430) readonly buffer Draws { GpuDraw draws[]; };
layout(set = 0, binding = 4, std430) readonly buffer Texcoords1 { vec2 texcoords1[]; };
layout(set = 0, binding = 5, std430) readonly buffer Tangents { vec4 tangents[]; };
layout(set = 0, binding = 6, std430) readonly buffer Colors { vec4 colors[]; };
layout(location = 3) out vec2 outTexcoord1;
layout(location = 4) out vec4 outTangent;  // scene space, w the bitangent's sign; 0: none
layout(location = 5) out vec4 outColor;

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inTexcoord;  // HAS_TEXCOORDS only
layout(location = 2) out vec2 outTexcoord;
layout(location = 0) out vec3 outWorldPos;
layout(location = 1) out vec3 outNormal;

void main() {
  const GpuInstance inst = instances[gl_InstanceIndex];  // includes the draw's firstInstance
  const vec4 world = inst.transform * vec4(inPosition, 1.0);
  outWorldPos = world.xyz;
  outNormal = mat3(inst.normalX.xyz, inst.normalY.xyz, inst.normalZ.xyz) * inNormal;
  const uint flags = draws[inst.info.x].flags;
  const uint v = uint(gl_VertexIndex);  // includes the draw's vertex offset
  outTexcoord1 = (flags & DRAW_UV1) != 0u ? texcoords1[v] : vec2(0.0);
  outColor = (flags & DRAW_COLORS) != 0u ? colors[v] : vec4(1.0);
  outTangent = vec4(0.0);
  if ((flags & DRAW_TANGENTS) != 0u) {  // a mirror flips the bitangent's handedness
    const vec4 t = tangents[v];
    outTangent = vec4(mat3(inst.transform) * t.xyz, (inst.info.y & INSTANCE_MIRRORED) != 0u ? -t.w : t.w);
  }
  if (HAS_TEXCOORDS) outTexcoord = inTexcoord;
  gl_Position = frame.viewProj * world;
}
