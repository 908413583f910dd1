#pragma once
// The in-memory scene every part shares: the baker writes it, the loader reads it, the renderer
// uploads it and the ray tracer traces it. It knows no GPU.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <memory>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/bounds.hpp"
#include "core/camera.hpp"
#include "core/view_or_vector.hpp"

namespace rtr {

struct BakedTexels;  // scene/baked_texels.hpp

// Texture slots: the course format's six in its order (docs/formats.md), then glTF's occlusion, which
// the course format does not store.
enum class TextureSlot : uint32_t { BaseColor, Roughness, Metalness, AlphaMask, NormalMap, Emissive, Occlusion, Count };
constexpr uint32_t kTextureSlotCount = uint32_t(TextureSlot::Count);
constexpr uint32_t kCourseSlotCount = 6;  // the slots the course format and MTL files carry
constexpr uint32_t kNoTexture = 0xFFFFFFFFu;

// How a texture is sampled: glTF samplers. OBJ/MTL textures repeat and filter trilinearly (the default).
enum class Wrap : uint8_t { Repeat, ClampToEdge, MirroredRepeat };
struct SamplerDesc {
  Wrap wrapU = Wrap::Repeat, wrapV = Wrap::Repeat;
  bool nearestMag = false, nearestMin = false;  // nearest texel instead of linear
  bool nearestMip = false;                      // nearest mip level instead of linear between two
  bool operator==(const SamplerDesc&) const = default;
};

struct Texture {
  std::filesystem::path path;  // absolute, or relative to Scene::baseDir; with `bytes`: a name for messages
  bool srgb = false;
  uint8_t channels = 4;  // channel count the slot needs; loaders force it
  // channels == 1: 0 takes the image as grey (its luminance: OBJ/MTL and course textures); 1-4 take its
  // R, G, B or A (glTF packs occlusion in R, roughness in G, metalness in B; a mask is the alpha).
  uint8_t sourceChannel = 0;
  SamplerDesc sampler;
  // The encoded image (PNG, JPEG) held in memory: a glTF data URI or buffer view. Null: read `path`.
  std::shared_ptr<const std::vector<uint8_t>> bytes;
  // The full mip chain as the GPU samples it (.rtrscene version 6, scene/baked_texels.hpp): when set, it is
  // used instead of decoding, and `path` only names the texture's source image in messages.
  std::shared_ptr<const BakedTexels> baked;
};

// KHR_texture_transform: uv' = offset + R(rotation) · (scale ⊙ uv), taken from texcoord set `texCoord`.
struct UvTransform {
  glm::vec2 offset{0.0f};
  float rotation = 0.0f;  // radians, counter-clockwise in uv space
  glm::vec2 scale{1.0f};
  uint32_t texCoord = 0;  // 0: Mesh::texcoords, 1: Mesh::texcoords1
  bool identity() const { return offset == glm::vec2(0.0f) && rotation == 0.0f && scale == glm::vec2(1.0f); }
};

enum MaterialFlags : uint32_t {
  kMaterialAlphaMasked = 1u << 0,
  kMaterialDoubleSided = 1u << 1,
  kMaterialLight = 1u << 2,  // the ray tracer's lights: material name contains "light"
  kMaterialBlend = 1u << 3,  // glTF alphaMode BLEND: drawn after the opaque ones, blended by its alpha
  kMaterialUnlit = 1u << 4,  // KHR_materials_unlit: the base colour is the result
  kMaterialGltf = 1u << 5,   // a glTF metallic-roughness material (its BRDF and texture conventions)
};

struct Material {
  std::string name;
  uint32_t flags = 0;
  // Physically based factors (Vulkan renderer, brief Part 2); they multiply the textures.
  glm::vec3 baseColor{1.0f};
  float roughness = 1.0f;
  float metalness = 0.0f;
  glm::vec3 emissive{0.0f};  // glTF: emissiveFactor × KHR_materials_emissive_strength
  float opacity = 1.0f;      // glTF baseColorFactor's alpha
  float alphaCutoff = 0.5f;  // alpha-masked: texels below it are cut out
  float normalScale = 1.0f;  // glTF normalTexture.scale
  float occlusionStrength = 1.0f;
  std::array<uint32_t, kTextureSlotCount> textures{kNoTexture, kNoTexture, kNoTexture, kNoTexture,
                                                   kNoTexture, kNoTexture, kNoTexture};
  std::array<UvTransform, kTextureSlotCount> uv{};  // per slot; identity for OBJ/MTL
  // Classic Blinn-Phong factors (ray tracer, brief Part 1). Defaults per docs/formats.md.
  glm::vec3 ka{0.5f}, kd{0.5f}, ks{0.5f}, ke{0.0f};
  float ns = 1.0f;
  float mirror = 0.0f;  // N_mirr
  float ior = 1.0f;     // N_ior
  float transparency = 0.0f;

  uint32_t texture(TextureSlot s) const { return textures[uint32_t(s)]; }
  bool blended() const { return (flags & kMaterialGltf) && (flags & kMaterialBlend); }  // glTF alphaMode BLEND
};

// A run of at most 124 triangles of one mesh (scene/clusters.hpp), with the bounds culling tests it by.
// Its members lie as .rtrscene's 40-byte record does, so that a loaded scene's clusters are the file's.
struct Cluster {
  glm::vec3 center{0.0f};  // bounding sphere, scene space
  float radius = 0.0f;
  glm::vec3 coneAxis{0.0f};  // normal cone (shaders/shared/cluster.h); cutoff >= 1: none
  float coneCutoff = 1.0f;
  uint32_t firstTriangle = 0, triangleCount = 0;  // triangles [first, first + count) of the mesh
};

// A cluster of a mesh's level-of-detail hierarchy (scene/cluster_lod.hpp, docs/virtual-geometry.md).
// Its triangles are numbered past the mesh's own: level 0 is the mesh's clusters (Mesh::clusters, the
// same triangles), and triangle t of ClusterLod::indices is triangle triangleCount() + t of the mesh, so
// a visibility id names any level's triangle as it names the mesh's.
// Its members lie as .rtrscene's 96-byte CLOD record does (a loaded scene's records are the file's).
struct LodCluster {
  uint32_t firstTriangle = 0, triangleCount = 0;
  uint32_t level = 0;      // 0: the mesh's own triangles
  float error = 0.0f;      // object-space error of the simplification that made it (level 0: 0)
  glm::vec3 center{0.0f};  // bounds of its triangles (culling)
  float radius = 0.0f;
  glm::vec3 coneAxis{0.0f};  // normal cone as Cluster's; cutoff >= 1: none
  float coneCutoff = 1.0f;
  glm::vec4 sphere{0.0f};  // where `error` applies (the group that made it; level 0: its bounds)
  glm::vec4 parentSphere{0.0f};
  float parentError = 0.0f;          // of the simplification that replaced it; LOD_ERROR_INFINITE: a root
  uint32_t reserved[3] = {0, 0, 0};  // the record's; always 0
};
struct ClusterLod {
  ViewOrVector<uint32_t> indices;          // the triangles of levels 1 and up, cluster by cluster; mesh vertices
  ViewOrVector<LodCluster> clusters;       // level 0 first (Mesh::clusters' order), then level by level
  uint32_t levels = 0;                     // 0: no hierarchy
  size_t triangles(uint32_t level) const;  // of that level's clusters
};

struct Mesh {
  std::string name;  // OBJ object/group name
  uint32_t material = 0;
  // The large arrays: owned vectors, or views of the mapped .rtrscene they were read from (a view is
  // copied once by the first code that changes it: core/view_or_vector.hpp).
  ViewOrVector<glm::vec3> positions;
  ViewOrVector<glm::vec3> normals;     // same count as positions
  ViewOrVector<glm::vec2> texcoords;   // empty when the source has none
  ViewOrVector<glm::vec2> texcoords1;  // a second uv set (glTF TEXCOORD_1); empty when none
  ViewOrVector<glm::vec4> tangents;    // xyz unit tangent, w ±1 bitangent sign (glTF); empty when none
  ViewOrVector<glm::vec4> colors;      // linear RGBA vertex colours (glTF COLOR_0, OBJ `v x y z r g b`); empty when none
  ViewOrVector<uint32_t> indices;      // triangle list, local to the mesh
  Bounds bounds;                       // object space (before any instance transform)
  ViewOrVector<Cluster> clusters;      // tile the triangles in order; empty until built (scene/clusters.hpp)
  ClusterLod lod;                      // the level-of-detail hierarchy; empty: none (scene/cluster_lod.hpp)

  uint32_t triangleCount() const { return uint32_t(indices.size() / 3); }
};

// A light in scene space. Point lights and the ray tracer's area lights (docs/formats.md); a headlight sits
// at the camera, wherever it is (the default light of a scene that has none: scene/lights.hpp).
struct Light {
  // Spot and Directional: glTF's KHR_lights_punctual.
  enum class Kind : uint32_t { Point, Area, Headlight, Spot, Directional };
  Kind kind = Kind::Point;
  glm::vec3 position{0.0f};                          // point light position, or the area light's centre
  glm::vec3 color{1.0f};                             // colour x intensity
  bool falloff = false;                              // inverse-square falloff with distance
  glm::vec3 corner{0.0f}, edge1{0.0f}, edge2{0.0f};  // area light: corner + s·edge1 + t·edge2
  glm::vec3 normal{0.0f};                            // area light: normal of its first face
  glm::vec3 direction{0.0f, 0.0f, -1.0f};            // spot and directional: the unit direction the light travels
  float innerConeCos = 1.0f, outerConeCos = 0.0f;    // spot: full inside the inner cone, none outside the outer
  float range = 0.0f;                                // > 0: no light beyond this distance (glTF range); 0: unbounded
  // Where to aim shadow ray `i` of `n` (n = 1: the centre; otherwise a stratified grid on the quad).
  glm::vec3 samplePoint(int i, int n) const;
};

// One placement of a mesh: glTF nodes that use the same mesh share its geometry (instances, not copies).
struct Instance {
  uint32_t mesh = 0;
  glm::mat4 transform{1.0f};  // object to scene space
};

struct Scene {
  std::filesystem::path baseDir;  // folder the texture paths are relative to
  std::vector<Texture> textures;
  std::vector<Material> materials;
  std::vector<Mesh> meshes;
  // Where the meshes are drawn. Empty: each mesh once, as it is (OBJ, the course format); otherwise only
  // these placements are drawn, and a mesh no instance names is not.
  std::vector<Instance> instances;
  std::optional<CameraPose> defaultView;
  float defaultFovYDeg = 0.0f;  // the stored camera's vertical field of view (glTF); 0: the tool's own
  // Lights stored with the scene (.rtrscene, the course format's standard light). Empty: the scene's
  // lights are its `*light*` geometry (scene/lights.hpp).
  std::vector<Light> lights;

  // Scene-space bounds of everything drawn (instances' transformed boxes).
  Bounds bounds() const;
};

}  // namespace rtr
