#version 460
// Full-screen triangle without vertex buffers: (-1,-1), (3,-1), (-1,3) cover the viewport.
void main() {
  const vec2 uv = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
  gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
