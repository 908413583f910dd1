#version 460
// Two triangles per rectangle, pulled from a storage buffer by gl_VertexIndex (no vertex buffers).
#extension GL_GOOGLE_include_directive : require
#include "text.h"

layout(set = 0, binding = 0, std430) readonly buffer Rects { TextRect rects[]; };
layout(push_constant) uniform Push { TextPush pc; };
layout(location = 0) out vec4 outColor;

void main() {
  const TextRect r = rects[gl_VertexIndex / 6];
  const int corner = int[6](0, 1, 2, 2, 1, 3)[gl_VertexIndex % 6];  // bit 0: right, bit 1: bottom
  const vec2 p = vec2((corner & 1) != 0 ? r.rect.z : r.rect.x, (corner & 2) != 0 ? r.rect.w : r.rect.y);
  gl_Position = vec4(p * pc.pixelToNdc - 1.0, 0.0, 1.0);
  outColor = r.color;
}
