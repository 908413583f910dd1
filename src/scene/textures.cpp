#include "scene/textures.hpp"

#include <algorithm>
#include <iostream>
#include <mutex>

#include "core/error.hpp"
#include "core/parallel.hpp"

namespace rtr {

std::vector<uint32_t> sampledTextures(const Scene& scene) {
  std::vector<uint32_t> used;
  std::vector<uint8_t> seen(scene.textures.size(), 0);
  for (const Mesh& m : scene.meshes) {
    if (m.texcoords.empty() || m.indices.empty()) continue;
    for (TextureSlot slot : kSampledSlots) {
      const uint32_t t = scene.materials.at(m.material).texture(slot);
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

void decodeTextures(const Scene& scene, std::span<const uint32_t> which,
                    const std::function<void(size_t, TexelData&&)>& use,
                    const std::function<void(const std::string&)>& warn) {
  std::mutex warnMutex;
  // A missing or broken texture must not stop a model from showing: warn, and show the checker instead.
  auto load = [&](const std::filesystem::path& file, int channels) {
    std::string why;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) {
      why = file.string() + ": texture file does not exist";
    } else {
      try {
        return loadImage(file, channels);
      } catch (const Error& e) {
        why = e.what();
      }
    }
    const std::lock_guard lock(warnMutex);
    const std::string msg = why + "; showing a magenta/black checker instead";
    if (warn) warn(msg);
    else std::cerr << "warning: " << msg << "\n";
    return fallbackTexels(channels);
  };
  parallelFor(which.size(), 0, [&](size_t i) {
    const Texture& t = scene.textures.at(which[i]);
    use(i, load(t.path.is_absolute() ? t.path : scene.baseDir / t.path, decodeChannels(t)));
  });
}

bool alphaTested(const Mesh& mesh, const Material& material) {
  return !mesh.texcoords.empty() && material.texture(TextureSlot::AlphaMask) != kNoTexture &&
         (material.flags & (kMaterialAlphaMasked | kMaterialDoubleSided));
}

}  // namespace rtr
