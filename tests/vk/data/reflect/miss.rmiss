#version 460
#extension GL_EXT_ray_tracing : require
layout(location = 0) rayPayloadInEXT vec3 payload;
layout(set = 0, binding = 3) uniform samplerCube sky;
void main() { payload = texture(sky, gl_WorldRayDirectionEXT).rgb; }
