#include "scene/textures.hpp"

#include <algorithm>
#include <iostream>
#include <mutex>

#include "core/error.hpp"
#include "core/parallel.hpp"
#include "scene/baked_texels.hpp"

namespace rtr {

std::span<const TextureSlot> sampledSlots(const Material& material) {
  if (material.flags & kMaterialGltf) return kGltfSampledSlots;
  return kSampledSlots;
}

std::vector<uint32_t> sampledTextures(const Scene& scene) {
  std::vector<uint32_t> used;
  std::vector<uint8_t> seen(scene.textures.size(), 0);
  for (const Mesh& m : scene.meshes) {
    if (m.texcoords.empty() || m.indices.empty()) continue;
    const Material& mat = scene.materials.at(m.material);
    for (TextureSlot slot : sampledSlots(mat)) {
      const uint32_t t = mat.texture(slot);
      if (t != kNoTexture && !seen.at(t)) {
        seen[t] = 1;
        used.push_back(t);
      }
    }
  }
  return used;
}

int decodeChannels(const Texture& t) { return t.channels == 1 ? 1 : 4; }
bool decodeSrgb(const Texture& t) { return t.srgb && decodeChannels(t) == 4; }

TexelData decodeTexture(const Scene& scene, const Texture& t) {
  if (t.baked) return unpackBakedLevel0(*t.baked);  // its channel already picked at bake time
  const int channels = decodeChannels(t);
  const bool pick = channels == 1 && t.sourceChannel > 0;  // one channel of a colour image
  TexelData d = t.bytes ? decodeImage(*t.bytes, t.path.string(), pick ? 4 : channels)
                        : loadImage(t.path.is_absolute() ? t.path : scene.baseDir / t.path, pick ? 4 : channels);
  if (pick) {
    const int c = std::min<int>(t.sourceChannel - 1, 3);
    for (size_t i = 0, n = size_t(d.width) * d.height; i < n; ++i) d.texels[i] = d.texels[i * 4 + c];
    d.texels.resize(size_t(d.width) * d.height);
    d.texels.shrink_to_fit();
    d.channels = 1;
  }
  return d;
}

TexelData fallbackTexels(int channels) {
  constexpr uint32_t kSize = 64, kCell = 8;
  TexelData t{kSize, kSize, uint32_t(channels), std::vector<uint8_t>(size_t(kSize) * kSize * channels)};
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x) {
      const bool on = ((x / kCell) + (y / kCell)) % 2 == 0;
      uint8_t* p = &t.texels[(size_t(y) * kSize + x) * channels];
      const uint8_t rgba[4] = {uint8_t(on ? 255 : 0), 0, uint8_t(on ? 255 : 0), 255};
      for (int c = 0; c < channels; ++c) p[c] = channels == 1 ? rgba[0] : rgba[c];
    }
  return t;
}

void decodeTextures(const Scene& scene, std::span<const uint32_t> which, const std::function<void(size_t, TexelData&&)>& use,
                    const std::function<void(const std::string&)>& warn, std::vector<uint8_t>* fellBack) {
  std::mutex warnMutex;
  if (fellBack) fellBack->assign(which.size(), 0);
  // A missing or broken texture must not stop a model from showing: warn, and show the checker instead.
  auto load = [&](size_t i, const Texture& t) {
    std::string why;
    std::error_code ec;
    const std::filesystem::path file = t.path.is_absolute() ? t.path : scene.baseDir / t.path;
    if (!t.bytes && !t.baked && !std::filesystem::is_regular_file(file, ec)) {
      why = file.string() + ": texture file does not exist";
    } else {
      try {
        return decodeTexture(scene, t);
      } catch (const Error& e) { why = e.what(); }
    }
    if (fellBack) (*fellBack)[i] = 1;
    const std::lock_guard lock(warnMutex);
    const std::string msg = why + "; showing a magenta/black checker instead";
    if (warn) warn(msg);
    else std::cerr << "warning: " << msg << "\n";
    return fallbackTexels(decodeChannels(t));
  };
  parallelFor(which.size(), 0, [&](size_t i) { use(i, load(i, scene.textures.at(which[i]))); });
}

bool alphaTested(const Mesh& mesh, const Material& material) {
  return !mesh.texcoords.empty() && material.texture(TextureSlot::AlphaMask) != kNoTexture &&
         (material.flags & (kMaterialAlphaMasked | kMaterialDoubleSided));
}

}  // namespace rtr
