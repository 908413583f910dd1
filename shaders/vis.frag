#version 460
// Visibility pass fragment stage: stores which triangle is visible (the instance's first id plus gl_PrimitiveID,
// which needs the geometryShader feature, frame.h); the compute pass vis_shade.comp shades it. Alpha-masked materials
// discard here exactly like pbr.frag (same texture, same implicit LOD and bias).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_nonuniform_qualifier : require
#include "frame.h"
#include "variants.h"

layout(push_constant) uniform Push { DrawPush draw; };
layout(location = 0) out uint outId;
layout(location = 1) flat in uint inFirstId;  // of the instance (frame.h)

// ALPHA_MASK only:
layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1, std430) readonly buffer Materials { GpuMaterial materials[]; };
layout(set = 1, binding = 0) uniform sampler2D textures[];
layout(location = 0) in vec2 inTexcoord;

void main() {
  if (ALPHA_MASK) {
    const GpuMaterial m = materials[draw.material];  // uniform per draw
    if (m.textures.w != NO_TEXTURE) {
      const vec4 r0 = m.uvTransform[2 * SLOT_MASK], r1 = m.uvTransform[2 * SLOT_MASK + 1];  // set 0's texcoords
      const vec4 mask = texture(textures[m.textures.w], vec2(dot(r0.xy, inTexcoord) + r0.z, dot(r1.xy, inTexcoord) + r1.z), frame.params.y);
      if (m.baseColor.a * ((m.textures2.w & MATERIAL_MASK_RED) != 0u ? mask.r : mask.a) < m.roughMetal.z) discard;
    }
  }
  outId = inFirstId + uint(gl_PrimitiveID);
}
