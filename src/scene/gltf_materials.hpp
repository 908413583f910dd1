#pragma once
// glTF materials, textures, samplers and images -> the scene's Material and Texture entries.
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "scene/gltf_accessors.hpp"
#include "scene/scene.hpp"

namespace rtr::gltf {

class Materials {
 public:
  // `note`/`warn` get messages without the file name (the caller adds it).
  Materials(const Json& root, Accessors& accessors, Scene& scene, std::function<void(const std::string&)> note,
            std::function<void(const std::string&)> warn);
  // The scene material of glTF material `index` (nullopt: the spec's default material), made on first use.
  uint32_t material(std::optional<uint32_t> index);
  size_t count() const { return materialsJ_.size(); }

 private:
  uint32_t make(const Json& m);
  uint32_t texture(const Json& info, TextureSlot slot, Material& mat, bool srgb, uint8_t channels, uint8_t sourceChannel);
  SamplerDesc sampler(const Json& s) const;
  void image(uint32_t i, Texture& t);

  Json root_;
  Accessors& acc_;
  Scene& scene_;
  std::function<void(const std::string&)> note_, warn_;
  std::vector<Json> materialsJ_, texturesJ_, imagesJ_, samplersJ_;
  std::vector<std::optional<uint32_t>> made_;
  std::optional<uint32_t> default_;
  std::vector<std::optional<Texture>> images_;  // path or bytes, per image
  std::map<std::tuple<uint32_t, uint32_t, bool, uint8_t, uint8_t>, uint32_t> textures_;
};

}  // namespace rtr::gltf
