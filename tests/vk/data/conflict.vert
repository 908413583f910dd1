#version 460
// Declares set 0 binding 1 as a uniform buffer; conflict.frag declares it as a sampler.
layout(set = 0, binding = 1) uniform Camera { mat4 viewProj; } camera;
layout(location = 0) in vec3 position;
void main() { gl_Position = camera.viewProj * vec4(position, 1.0); }
