#pragma once
// Textures of the tracer's PBR mode, sampled as the GPU renderer samples them (render/gpu_scene.cpp):
// the same files and texels (scene/textures.hpp), the same mip chain, trilinear filtering with REPEAT
// addressing and no anisotropy. Only the level of detail is chosen differently (ray cones, not screen
// derivatives; trace/tracer.cpp).
#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/image.hpp"
#include "scene/baked_texels.hpp"
#include "scene/scene.hpp"
#include "scene/texture_cache.hpp"

namespace rtr::trace {

// One texture as the GPU holds it: every level from the float64 box-filter reference of the GPU's mip
// chain (core/mip_reference.hpp, each level from the previous one as the compute chain does) rounded to
// 8 bits like the GPU's image, and decoded to linear on read (sRGB before filtering, as Vulkan does).
class MipTexture {
 public:
  // Throws rtr::Error for an empty or malformed image. The sampler's wrap modes address texels (its
  // nearest filters are not modelled: always trilinear).
  MipTexture(const TexelData& image, bool srgb, const SamplerDesc& sampler = {});
  // From a whole lossless chain made by this class before (the texture cache's entries): no filtering.
  MipTexture(const BakedTexels& chain, bool srgb, const SamplerDesc& sampler = {});
  // The chain laid out as a lossless baked texture's (BakedTexels::levelOffsets), for the texture cache.
  std::vector<uint8_t> chainBytes() const;

  // Trilinear sample at uv (the sampler's wrap modes) at level of detail `lod` (clamped to the chain; NaN reads level
  // 0). A one-channel texture reads (r, 0, 0, 1), as R8_UNORM does.
  glm::vec4 sample(glm::vec2 uv, float lod) const;
  // The level of detail of a footprint `uvWidth` wide in texture coordinates: log2(uvWidth · √(w·h)).
  float lod(float uvWidth) const;

  uint32_t width() const { return levels_[0].width; }
  uint32_t channels() const { return channels_; }
  uint32_t height() const { return levels_[0].height; }
  uint32_t levels() const { return uint32_t(levels_.size()); }

 private:
  struct Level {
    uint32_t width, height;
    std::vector<uint8_t> texels;
  };
  glm::vec4 bilinear(const Level& level, glm::vec2 uv) const;

  std::vector<Level> levels_;
  uint32_t channels_;
  bool srgb_;
  SamplerDesc sampler_;
  float halfLog2Area_;  // 0.5·log2(width·height)
};

// What a surface point's material gives the BRDF: shaders/material.glsl's Surface.
struct SurfaceInputs {
  glm::vec3 baseColor;
  float roughness, metalness;
  glm::vec3 emissive;
  float alpha;
};
SurfaceInputs materialFactors(const Material& m);  // factors only (a mesh without texcoords)

// The texture coordinates of a surface point: both sets (glTF TEXCOORD_0 and _1).
struct SurfaceUv {
  glm::vec2 uv0{0.0f}, uv1{0.0f};
};
// The uv a material's slot samples: its set, through its KHR_texture_transform
// (uv' = offset + R · (scale ⊙ uv), R turning counter-clockwise in uv space, whose v points down), and
// the factor its transform scales a footprint by. Identity: uv0 itself, factor 1.
glm::vec2 slotUv(const Material& m, TextureSlot slot, const SurfaceUv& uv, float* footprintScale = nullptr);

// The textures a scene's PBR shading samples (only those scene/textures.hpp's sampledTextures lists),
// decoded and mip-mapped on all cores, or their chains taken from `cache` where it has them (those it had
// not are stored). Throws rtr::Error naming a file that is missing or undecodable.
class SceneTextures {
 public:
  explicit SceneTextures(const Scene& scene, TextureCache* cache = nullptr);

  // material.glsl's fetchSurface: factors × textures at uv. uvWidth: the ray cone's width at the hit in
  // texture-coordinate units (the level of detail follows from it and each texture's size).
  SurfaceInputs fetch(const Material& m, const SurfaceUv& uv, float uvWidth) const;
  // The alpha-mask texture's alpha (a one-channel mask, glTF's base colour alpha: its value), 1 without.
  float alpha(const Material& m, const SurfaceUv& uv, float uvWidth) const;
  // One slot's sample (one channel: (r, 0, 0, 1)), or `none` where the material has no texture there.
  glm::vec4 sample(const Material& m, TextureSlot slot, const SurfaceUv& uv, float uvWidth, glm::vec4 none) const;

  size_t count() const { return textures_.size(); }
  double loadSeconds() const { return seconds_; }    // decoding and mip building, wall time
  uint32_t cacheHits() const { return cacheHits_; }  // of count(), chains taken from the texture cache

 private:
  const MipTexture* texture(const Material& m, TextureSlot slot) const;
  std::vector<uint32_t> index_;  // scene texture -> textures_ index (kNoTexture: not sampled)
  std::vector<MipTexture> textures_;
  double seconds_ = 0;
  uint32_t cacheHits_ = 0;
};

}  // namespace rtr::trace
