#version 460
// Storage images of several formats, runtime descriptor arrays, nested push-constant structs and
// specialization constants.
#extension GL_EXT_nonuniform_qualifier : require
layout(local_size_x_id = 0, local_size_y = 4) in;
layout(constant_id = 1) const bool kUseSky = true;
layout(constant_id = 2) const int kTaps = -3;
layout(constant_id = 3) const float kScale = 0.5;
layout(set = 0, binding = 0, rgba8) uniform image2D colorImage;
layout(set = 0, binding = 1, r32ui) uniform uimage2D counter;
layout(set = 0, binding = 2, rgba16f) uniform image2D hdr;
layout(set = 0, binding = 3, rg32f) uniform image2D motion;
layout(set = 0, binding = 4, r11f_g11f_b10f) uniform image2D packedColor;
layout(set = 1, binding = 0) uniform texture2D textures[];
layout(set = 2, binding = 0) uniform sampler samplers[4];
struct Light { vec3 position; float radius; vec4 color; };
struct Frame { mat4 viewProj; Light lights[2]; };
layout(push_constant) uniform Push { uint textureIndex; Frame frame; } pc;
void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  vec4 c = texture(sampler2D(textures[nonuniformEXT(pc.textureIndex)], samplers[kTaps & 3]), vec2(p) * kScale);
  c += pc.frame.lights[1].color * pc.frame.viewProj[0];
  imageStore(colorImage, p, kUseSky ? c : vec4(0));
  imageAtomicAdd(counter, p, 1u);
  imageStore(hdr, p, c + imageLoad(motion, p).xyxy);
  imageStore(packedColor, p, c);
}
