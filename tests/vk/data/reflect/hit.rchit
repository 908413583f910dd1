#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_nonuniform_qualifier : require
layout(location = 0) rayPayloadInEXT vec3 payload;
hitAttributeEXT vec2 barycentrics;
layout(set = 0, binding = 2) uniform Camera { mat4 viewInverse; mat4 projInverse; } camera;
layout(set = 1, binding = 0, std430) readonly buffer Colors { vec4 color[]; } colors[];
void main() {
  payload = colors[nonuniformEXT(gl_InstanceCustomIndexEXT)].color[gl_PrimitiveID].rgb * barycentrics.x +
            camera.viewInverse[0].xyz;
}
