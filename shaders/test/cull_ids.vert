#version 460
// Test pipeline (tests/render/cull_test.cpp): draws cluster ranges and writes (draw, triangle) ids. The
// draw's firstInstance carries the cluster's first triangle, so ids match a draw of the whole mesh.
layout(location = 0) in vec3 position;
layout(push_constant) uniform Push { mat4 viewProj; uint draw; uint pad0, pad1, pad2; } pc;
layout(location = 0) flat out uint firstTriangle;

void main() {
  firstTriangle = uint(gl_InstanceIndex);
  gl_Position = pc.viewProj * vec4(position, 1.0);
}
