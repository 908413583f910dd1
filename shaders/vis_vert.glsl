// Visibility pass vertex stage: positions only, plus texcoords where the fragment stage alpha-tests.
#extension GL_GOOGLE_include_directive : require
#include "frame.h"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };

layout(location = 0) in vec3 inPosition;
#if ALPHA_MASK
layout(location = 1) in vec2 inTexcoord;
layout(location = 0) out vec2 outTexcoord;
#endif

void main() {
#if ALPHA_MASK
  outTexcoord = inTexcoord;
#endif
  gl_Position = frame.viewProj * vec4(inPosition, 1.0);
}
