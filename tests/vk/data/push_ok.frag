#version 460
#extension GL_EXT_nonuniform_qualifier : require
// Shares push_a.vert's block and adds a runtime-sized sampled-image array.
layout(push_constant) uniform Push { layout(offset = 64) vec4 tint; } pc;
layout(set = 1, binding = 0) uniform sampler2D textures[];
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;
void main() { color = texture(textures[nonuniformEXT(int(pc.tint.w))], uv) * pc.tint; }
