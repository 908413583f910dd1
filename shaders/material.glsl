// Material inputs of a fragment: factors x textures, from the material buffer and the scene's texture
// array (sized by the scene; only textures that some material uses are in it).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_nonuniform_qualifier : require
#include "frame.h"
#include "brdf.h"
#include "variants.h"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1, std430) readonly buffer Materials { GpuMaterial materials[]; };
layout(push_constant) uniform Push { DrawPush draw; };
layout(set = 1, binding = 0) uniform sampler2D textures[];  // HAS_TEXCOORDS only

layout(location = 0) in vec3 inWorldPos;
layout(location = 1) in vec3 inNormal;
layout(location = 3) in vec2 inTexcoord1;
layout(location = 4) in vec4 inTangent;
layout(location = 5) in vec4 inColor;
layout(location = 2) in vec2 inTexcoord;  // HAS_TEXCOORDS only

struct Surface {
  vec3 baseColor;
  float roughness;
  float metalness;
  vec3 emissive;
  float alpha;
  float occlusion;  // multiplies the ambient term (1: none)
  vec3 normal;      // the interpolated normal, bent by the normal map where there is one
};

// Slot `slot`'s texcoords: its set, its transform (the identity for OBJ materials).
vec2 slotUv(GpuMaterial m, uint slot) {
  const vec4 r0 = m.uvTransform[2 * slot], r1 = m.uvTransform[2 * slot + 1];
  const vec2 uv = r0.w > 0.5 ? inTexcoord1 : inTexcoord;
  return vec2(dot(r0.xy, uv) + r0.z, dot(r1.xy, uv) + r1.z);
}
// The index is the same for the whole draw (push constant), so no nonuniformEXT is needed.
vec4 sampleOr(GpuMaterial m, uint index, uint slot, vec4 fallback) {
  return index == NO_TEXTURE ? fallback : texture(textures[index], slotUv(m, slot), frame.params.y);
}

Surface fetchSurface() {
  GpuMaterial m = materials[draw.material];
  Surface s;
  s.baseColor = m.baseColor.rgb;
  s.roughness = m.roughMetal.x;
  s.metalness = m.roughMetal.y;
  s.emissive = m.emissive.rgb;
  s.alpha = m.baseColor.a;
  s.occlusion = 1.0;
  s.normal = inNormal;
  s.baseColor *= inColor.rgb;  // 1 without vertex colours
  s.alpha *= inColor.a;
  if (!HAS_TEXCOORDS) return s;
  s.baseColor *= sampleOr(m, m.textures.x, SLOT_BASE, vec4(1.0)).rgb;
  s.roughness *= sampleOr(m, m.textures.y, SLOT_ROUGHNESS, vec4(1.0)).r;
  s.metalness *= sampleOr(m, m.textures.z, SLOT_METALNESS, vec4(1.0)).r;
  const vec4 mask = sampleOr(m, m.textures.w, SLOT_MASK, vec4(1.0));
  s.alpha *= (m.textures2.w & MATERIAL_MASK_RED) != 0u ? mask.r : mask.a;
  s.emissive *= sampleOr(m, m.textures2.x, SLOT_EMISSIVE, vec4(1.0)).rgb;
  if (m.textures2.y != NO_TEXTURE) s.occlusion = 1.0 + m.roughMetal.w * (sampleOr(m, m.textures2.y, SLOT_OCCLUSION, vec4(1.0)).r - 1.0);
  if (m.textures2.z != NO_TEXTURE && inTangent.xyz != vec3(0.0)) {
    // Tangent space: t, b = w (n x t), n; the map's xy scaled by normalScale (glTF).
    const vec3 tn = (sampleOr(m, m.textures2.z, SLOT_NORMAL, vec4(0.5, 0.5, 1.0, 1.0)).xyz * 2.0 - 1.0) * vec3(m.emissive.w, m.emissive.w, 1.0);
    const vec3 n = normalize(inNormal), t = normalize(inTangent.xyz - n * dot(n, inTangent.xyz));
    s.normal = t * tn.x + cross(n, t) * (inTangent.w * tn.y) + n * tn.z;
  }
  return s;
}

bool cutOut(Surface s) { return s.alpha < materials[draw.material].roughMetal.z; }
int brdfOf() { return (materials[draw.material].textures2.w & MATERIAL_GGX) != 0u ? BRDF_GGX : BRDF_BECKMANN; }
bool unlit() { return (materials[draw.material].textures2.w & MATERIAL_UNLIT) != 0u; }

// Two-sided materials light their back faces with the flipped normal.
vec3 shadingNormal(Surface s) { return gl_FrontFacing ? s.normal : -s.normal; }
