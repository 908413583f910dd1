// The scene passes' variants: one source per pass, each variant a value of these specialization constants
// (renderer.cpp sets them; vk::specialize folds them away with the code, inputs and descriptors that the
// variant does not use, so reflection gives each variant its own layout and vertex streams).
#ifndef RTR_SHADERS_SHARED_VARIANTS_H
#define RTR_SHADERS_SHARED_VARIANTS_H

#define VARIANT_TEXCOORDS 0   // the scene has texture coordinates: materials' textures are sampled
#define VARIANT_ALPHA_MASK 1  // the fragment stage cuts out by the material's alpha (foliage)
#define VARIANT_VIS_BUFFER 2  // vis_shade reads the compute rasteriser's 64-bit buffer, not the id image
#define VARIANT_ENV 3         // the shaded view adds an environment's light (env_light.glsl) and shows its backdrop
#define VARIANT_BLEND 4       // pbr.frag in the transparency pass: alpha out, the compute raster's depth tested
#define VARIANT_MATERIAL_EXTRAS 5  // vis_shade: some draw has glTF's extras (texture transforms, the second uv set,
                                   // vertex colours, tangents, normal and occlusion maps, unlit, GGX; GpuScene)
#define VARIANT_DISPLAY 6     // vis_shade writes the target's sRGB-encoded bytes, not the linear image (no post pass)
#define VARIANT_IDENTITY 7    // vis_shade: every instance's transform is the identity (GpuScene): none applied

#ifndef __cplusplus
layout(constant_id = VARIANT_TEXCOORDS) const bool HAS_TEXCOORDS = true;
layout(constant_id = VARIANT_ALPHA_MASK) const bool ALPHA_MASK = false;
layout(constant_id = VARIANT_VIS_BUFFER) const bool VIS_BUFFER = false;
layout(constant_id = VARIANT_ENV) const bool HAS_ENV = false;
layout(constant_id = VARIANT_BLEND) const bool BLEND = false;
layout(constant_id = VARIANT_MATERIAL_EXTRAS) const bool MATERIAL_EXTRAS = true;
layout(constant_id = VARIANT_DISPLAY) const bool DISPLAY = false;
layout(constant_id = VARIANT_IDENTITY) const bool IDENTITY = false;
#endif
#endif
