#pragma once
// The in-memory scene every part shares: the baker writes it, the loader reads it, the renderer
// uploads it and the ray tracer traces it. It knows no GPU.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/bounds.hpp"
#include "core/camera.hpp"

namespace rtr {

// Texture slots in the course format's order (FORMATS.md §1).
enum class TextureSlot : uint32_t { BaseColor, Roughness, Metalness, AlphaMask, NormalMap, Emissive, Count };
constexpr uint32_t kTextureSlotCount = uint32_t(TextureSlot::Count);
constexpr uint32_t kNoTexture = 0xFFFFFFFFu;

struct Texture {
  std::filesystem::path path;  // absolute, or relative to Scene::baseDir
  bool srgb = false;
  uint8_t channels = 4;        // channel count the slot needs; loaders force it
};

enum MaterialFlags : uint32_t {
  kMaterialAlphaMasked = 1u << 0,
  kMaterialDoubleSided = 1u << 1,
  kMaterialLight = 1u << 2,  // the ray tracer's lights: material name contains "light"
};

struct Material {
  std::string name;
  uint32_t flags = 0;
  // Physically based factors (Vulkan renderer, brief Part 2); they multiply the textures.
  glm::vec3 baseColor{1.0f};
  float roughness = 1.0f;
  float metalness = 0.0f;
  glm::vec3 emissive{0.0f};
  std::array<uint32_t, kTextureSlotCount> textures{kNoTexture, kNoTexture, kNoTexture,
                                                   kNoTexture, kNoTexture, kNoTexture};
  // Classic Blinn-Phong factors (ray tracer, brief Part 1). Defaults per FORMATS.md §2.
  glm::vec3 ka{0.5f}, kd{0.5f}, ks{0.5f}, ke{0.0f};
  float ns = 1.0f;
  float mirror = 0.0f;  // N_mirr
  float ior = 1.0f;     // N_ior
  float transparency = 0.0f;

  uint32_t texture(TextureSlot s) const { return textures[uint32_t(s)]; }
};

// A run of at most 124 triangles of one mesh (scene/clusters.hpp), with the bounds culling tests it by.
struct Cluster {
  uint32_t firstTriangle = 0, triangleCount = 0;  // triangles [first, first + count) of the mesh
  glm::vec3 center{0.0f};                         // bounding sphere, scene space
  float radius = 0.0f;
  glm::vec3 coneAxis{0.0f};                       // normal cone (shaders/shared/cluster.h); cutoff >= 1: none
  float coneCutoff = 1.0f;
};

struct Mesh {
  std::string name;  // OBJ object/group name
  uint32_t material = 0;
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;    // same count as positions
  std::vector<glm::vec2> texcoords;  // empty when the source has none
  std::vector<uint32_t> indices;     // triangle list, local to the mesh
  Bounds bounds;
  std::vector<Cluster> clusters;     // tile the triangles in order; empty until built (scene/clusters.hpp)

  uint32_t triangleCount() const { return uint32_t(indices.size() / 3); }
};

// A light in scene space. Point lights and the ray tracer's area lights (FORMATS.md §2); a headlight sits
// at the camera, wherever it is (the default light of a scene that has none: scene/lights.hpp).
struct Light {
  enum class Kind : uint32_t { Point, Area, Headlight };
  Kind kind = Kind::Point;
  glm::vec3 position{0.0f};  // point light position, or the area light's centre
  glm::vec3 color{1.0f};     // colour x intensity
  bool falloff = false;      // inverse-square falloff with distance
  glm::vec3 corner{0.0f}, edge1{0.0f}, edge2{0.0f};  // area light: corner + s·edge1 + t·edge2
  glm::vec3 normal{0.0f};    // area light: normal of its first face
  // Where to aim shadow ray `i` of `n` (n = 1: the centre; otherwise a stratified grid on the quad).
  glm::vec3 samplePoint(int i, int n) const;
};

struct Scene {
  std::filesystem::path baseDir;  // folder the texture paths are relative to
  std::vector<Texture> textures;
  std::vector<Material> materials;
  std::vector<Mesh> meshes;
  std::optional<CameraPose> defaultView;
  // Lights stored with the scene (.rtrscene, the course format's standard light). Empty: the scene's
  // lights are its `*light*` geometry (scene/lights.hpp).
  std::vector<Light> lights;

  Bounds bounds() const {
    Bounds b;
    for (const Mesh& m : meshes) b.extend(m.bounds);
    return b;
  }
};

}  // namespace rtr
