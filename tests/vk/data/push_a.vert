#version 460
layout(push_constant) uniform Push { mat4 model; vec4 tint; } pc;
layout(location = 0) in vec3 position;
layout(location = 1) in vec2 uv;
layout(location = 0) out vec2 outUv;
void main() { gl_Position = pc.model * vec4(position, 1.0); outUv = uv; }
