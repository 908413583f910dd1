// Structs shared by the renderer's C++ and its shaders: one definition on both sides of the boundary.
// Layouts use only vec4/mat4/uvec4 so std140 and std430 agree with C++ (GLM) without padding rules.
#ifndef RTR_SHADERS_SHARED_FRAME_H
#define RTR_SHADERS_SHARED_FRAME_H

#include "lights.h"

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace rtr::shader {
using namespace glm;
typedef uint32_t uint;
#endif

// View modes (keys 1-7 and BRDF-term views; --mode N).
#define VIEW_SHADED 1
#define VIEW_MIP_LEVEL 2
#define VIEW_LINEAR_DEPTH 3
#define VIEW_DEPTH_DERIVATIVES 4
#define VIEW_NORMAL 5
#define VIEW_VIEW_DIR 6
#define VIEW_LIGHT_DIR 7
#define VIEW_BRDF_D 8
#define VIEW_BRDF_F 9
#define VIEW_BRDF_G 10
#define VIEW_DIFFUSE 11
#define VIEW_SPECULAR 12
#define VIEW_ALBEDO 13      // unlit base colour: plain textured rasterisation, the speed baseline
#define VIEW_ENV_DIFFUSE 14   // the environment's diffuse term alone (env_light.glsl; black without one)
#define VIEW_ENV_SPECULAR 15  // the environment's specular term alone
#define VIEW_COUNT 15

// Per-frame constants (uniform buffer, std140).
struct FrameUniforms {
  mat4 viewProj;
  mat4 view;
  vec4 cameraPos;     // xyz world position
  vec4 ambient;       // rgb constant ambient illumination
  vec4 params;        // x: view mode, y: mip LOD bias, z: near, w: far
  // Visibility path: a (not normalised) world-space direction of the ray through pixel coordinate
  // (x, y) is rayDir + x rayDx + y rayDy (pixel centres at .5); rays start at cameraPos.
  vec4 rayDir;
  vec4 rayDx;
  vec4 rayDy;
  uvec4 lightCount;   // x: lights in use (<= MAX_LIGHTS); debug views use the first.
                      // y: 1 where the sampler takes the nearest mip level (the mip view shows whole levels)
  GpuLight lights[MAX_LIGHTS];
  // Light from an environment (docs/environment.md; its cubes are in world space, rotation applied) and the
  // backdrop. x: the specular cube's last level (roughness 1); y: how the backdrop shows the environment
  // (ENV_BACKDROP_COLOR: not at all, the colour instead; 0: sharp, the source cube; > 0: the specular cube
  // at that roughness); z: the split-sum table's width; w: the rotation about +y (radians) of the
  // equirectangular map, which is kept as it came.
  vec4 environment;
  vec4 background;    // rgb: linear colour of pixels nothing covers where the environment does not show
  uvec4 options;      // x: the BRDF of every material, 1 + BRDF_*; 0: each material's own (MATERIAL_GGX)
};
#define ENV_BACKDROP_COLOR -1.0f

// Material factors (storage buffer, std430). Texture indices index the scene's texture array;
// 0xFFFFFFFF: no texture (the factor alone is used).
// OBJ/course materials: opacity 1, cutoff 0.5, no occlusion texture, no flags (today's shading exactly).
struct GpuMaterial {
  vec4 baseColor;     // rgb factor, a opacity (glTF baseColorFactor's alpha; it multiplies the mask)
  vec4 emissive;      // rgb factor, w normal scale (glTF normalTexture.scale)
  vec4 roughMetal;    // x roughness, y metalness, z alpha cutoff (alpha below it is cut out),
                      // w occlusion strength (glTF: ambient x (1 + strength (occlusion - 1)))
  uvec4 textures;     // x baseColor, y roughness, z metalness, w alphaMask
  uvec4 textures2;    // x emissive, y occlusion (its red), z normal map, w MATERIAL_* flags
  // Per texture slot s (scene.hpp's TextureSlot order): uv' = (dot(r0.xy, uv) + r0.z, dot(r1.xy, uv) + r1.z)
  // with r0 = uvTransform[2 s], r1 = uvTransform[2 s + 1], uv the texcoord set r0.w (0 or 1); the
  // identity for OBJ (exact). KHR_texture_transform.
  vec4 uvTransform[14];
};
#define SLOT_BASE 0
#define SLOT_ROUGHNESS 1
#define SLOT_METALNESS 2
#define SLOT_MASK 3
#define SLOT_NORMAL 4
#define SLOT_EMISSIVE 5
#define SLOT_OCCLUSION 6
#define MATERIAL_UNLIT 1u     // KHR_materials_unlit: the base colour is the result
#define MATERIAL_MASK_RED 2u  // the alpha-mask texture is one channel (glTF: the base colour's alpha): read .r
#define MATERIAL_GGX 4u       // glTF materials: brdf.h's BRDF_GGX (others: the brief's Beckmann)

// Per-draw push constants.
struct DrawPush {
  uint material;
  uint opaqueWidth;   // transparency pass: the compute rasteriser's row length (its depth tests), else 0
};

// One placement of a mesh (storage buffer, std430, 128 bytes), indexed by gl_InstanceIndex in the
// hardware paths and named by the high bits of a visibility id. A scene without instances gets one
// identity instance per draw, in draw order (instance i draws GpuDraw i).
struct GpuInstance {
  mat4 transform;     // object to scene space
  vec4 normalX;       // columns of the inverse transpose of transform's upper 3x3 (normals)
  vec4 normalY;
  vec4 normalZ;
  uvec4 info;         // x: its GpuDraw, y: INSTANCE_* flags, z: its first visibility id (below), w: 0
};
#define INSTANCE_MIRRORED 1u  // negative determinant: the winding flips (front = clockwise on screen)

// One draw of the scene, for the visibility path's shading pass (storage buffer, std430, 16 bytes).
struct GpuDraw {
  uint material;
  uint firstIndex;    // in the index buffer of its type
  uint vertexOffset;
  uint flags;         // DRAW_*
};
#define DRAW_INDEX16 1u   // 16-bit indices (two per 32-bit word)
#define DRAW_TEXTURED 2u  // has texcoords: sample the material's textures
#define DRAW_COLORS 4u    // has vertex colours (glTF COLOR_0): they multiply the base colour and alpha
#define DRAW_TANGENTS 8u  // has tangents (xyz, w the bitangent's sign): normal maps apply
#define DRAW_UV1 16u      // has a second texcoord set

// Visibility target (R32_UINT): the instance's first id (GpuInstance::info.z) + gl_PrimitiveID; VIS_EMPTY
// where nothing was drawn. Instances take consecutive ranges, each as long as its draw's primitives
// (hierarchy included), so the ids count the triangles the scene can draw: 32 bits hold 4 G of them,
// whatever the instance count and mesh sizes. An id's instance is found through a page table
// (GpuScene::visIdPages: per 2^idPageShift ids, the instance holding the first), then a few steps.
#define VIS_EMPTY 0xFFFFFFFFu
struct VisShadePush {
  uint idPageShift;
  uint clearIds;  // VIS_BUFFER: each word read written back to all ones (ComputeRaster::foldClear)
};
#define VIS_GROUP_X 8     // shading pass workgroup
#define VIS_GROUP_Y 8

#define NO_TEXTURE 0xFFFFFFFFu

#ifdef __cplusplus
}  // namespace rtr::shader
#endif
#endif
