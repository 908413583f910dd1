#version 460
// Dear ImGui's triangles (src/apps/view/imgui_pass.cpp), vertices and 16-bit indices pulled from storage
// buffers by gl_VertexIndex (no vertex or index buffers). ImDrawVert: pos, uv (floats), RGBA8 colour.
layout(set = 0, binding = 0, std430) readonly buffer Vertices { uint verts[]; };   // 5 words per vertex
layout(set = 0, binding = 1, std430) readonly buffer Indices { uint indices[]; };  // two 16-bit indices per word
layout(push_constant) uniform Push {
  vec2 scale;        // pixels -> NDC
  vec2 translate;
  uint vertexBase;   // added to each index: the draw list's first vertex
} pc;
layout(location = 0) out vec2 outUv;
layout(location = 1) out vec4 outColor;

void main() {
  const uint i = uint(gl_VertexIndex);
  const uint word = indices[i >> 1];
  const uint v = 5u * (pc.vertexBase + ((i & 1u) != 0u ? word >> 16 : word & 0xFFFFu));
  const vec2 pos = uintBitsToFloat(uvec2(verts[v], verts[v + 1]));
  outUv = uintBitsToFloat(uvec2(verts[v + 2], verts[v + 3]));
  outColor = unpackUnorm4x8(verts[v + 4]);  // written as is: the target holds sRGB-encoded bytes already
  gl_Position = vec4(pos * pc.scale + pc.translate, 0.0, 1.0);
}
