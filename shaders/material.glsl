// Material inputs of a fragment: factors x textures, from the material buffer and the scene's texture
// array (sized by the scene; only textures that some material uses are in it).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_nonuniform_qualifier : require
#include "frame.h"
#include "brdf.h"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1, std430) readonly buffer Materials { GpuMaterial materials[]; };
layout(push_constant) uniform Push { DrawPush draw; };
#if HAS_TEXCOORDS
layout(set = 1, binding = 0) uniform sampler2D textures[];
#endif

layout(location = 0) in vec3 inWorldPos;
layout(location = 1) in vec3 inNormal;
#if HAS_TEXCOORDS
layout(location = 2) in vec2 inTexcoord;
#endif

struct Surface {
  vec3 baseColor;
  float roughness;
  float metalness;
  vec3 emissive;
  float alpha;
  float occlusion;  // multiplies the ambient term (1: none)
};

#if HAS_TEXCOORDS
// The index is the same for the whole draw (push constant), so no nonuniformEXT is needed.
vec4 sampleOr(uint index, vec4 fallback) {
  return index == NO_TEXTURE ? fallback : texture(textures[index], inTexcoord, frame.params.y);
}
#endif

Surface fetchSurface() {
  GpuMaterial m = materials[draw.material];
  Surface s;
  s.baseColor = m.baseColor.rgb;
  s.roughness = m.roughMetal.x;
  s.metalness = m.roughMetal.y;
  s.emissive = m.emissive.rgb;
  s.alpha = m.baseColor.a;
  s.occlusion = 1.0;
#if HAS_TEXCOORDS
  s.baseColor *= sampleOr(m.textures.x, vec4(1.0)).rgb;
  s.roughness *= sampleOr(m.textures.y, vec4(1.0)).r;
  s.metalness *= sampleOr(m.textures.z, vec4(1.0)).r;
  const vec4 mask = sampleOr(m.textures.w, vec4(1.0));
  s.alpha *= (m.textures2.w & MATERIAL_MASK_RED) != 0u ? mask.r : mask.a;
  s.emissive *= sampleOr(m.textures2.x, vec4(1.0)).rgb;
  if (m.textures2.y != NO_TEXTURE) s.occlusion = 1.0 + m.roughMetal.w * (sampleOr(m.textures2.y, vec4(1.0)).r - 1.0);
#endif
  return s;
}

bool cutOut(Surface s) { return s.alpha < materials[draw.material].roughMetal.z; }
int brdfOf() { return (materials[draw.material].textures2.w & MATERIAL_GGX) != 0u ? BRDF_GGX : BRDF_BECKMANN; }
bool unlit() { return (materials[draw.material].textures2.w & MATERIAL_UNLIT) != 0u; }

// Two-sided materials light their back faces with the flipped normal.
vec3 shadingNormal() { return gl_FrontFacing ? inNormal : -inNormal; }
