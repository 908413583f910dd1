// Scene vertex stage. Each input is its own tightly packed stream; the texcoord stream exists only in
// the textured variant (a scene without texcoords binds none).
#extension GL_GOOGLE_include_directive : require
#include "frame.h"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
#if HAS_TEXCOORDS
layout(location = 2) in vec2 inTexcoord;
layout(location = 2) out vec2 outTexcoord;
#endif
layout(location = 0) out vec3 outWorldPos;
layout(location = 1) out vec3 outNormal;

void main() {
  // The scene is baked in world space: no model matrix.
  outWorldPos = inPosition;
  outNormal = inNormal;
#if HAS_TEXCOORDS
  outTexcoord = inTexcoord;
#endif
  gl_Position = frame.viewProj * vec4(inPosition, 1.0);
}
