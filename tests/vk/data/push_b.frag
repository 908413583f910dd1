#version 460
// Same push block bytes as push_a.vert but laid out differently: a float where push_a has a mat4.
layout(push_constant) uniform Push { float scale; } pc;
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;
void main() { color = vec4(uv * pc.scale, 0.0, 1.0); }
