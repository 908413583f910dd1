#version 460
// Input attachments: the G-buffer read back in a later subpass.
layout(input_attachment_index = 0, set = 0, binding = 0) uniform subpassInput albedo;
layout(input_attachment_index = 2, set = 0, binding = 1) uniform subpassInput normal;
layout(location = 0) out vec4 color;
void main() { color = subpassLoad(albedo) * max(dot(subpassLoad(normal).xyz, vec3(0, 0, 1)), 0.0); }
