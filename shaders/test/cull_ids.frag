#version 460
// (draw, triangle of the mesh) per pixel; see cull_ids.vert.
layout(push_constant) uniform Push { mat4 viewProj; uint draw; uint pad0, pad1, pad2; } pc;
layout(location = 0) flat in uint firstTriangle;
layout(location = 0) out uvec2 id;

void main() { id = uvec2(pc.draw, firstTriangle + uint(gl_PrimitiveID)); }
