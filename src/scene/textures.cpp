#include "scene/textures.hpp"

#include <algorithm>
#include <atomic>
#include <future>
#include <thread>

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

void decodeTextures(const Scene& scene, std::span<const uint32_t> which,
                    const std::function<void(size_t, TexelData&&)>& use) {
  std::atomic<size_t> next{0};
  std::vector<std::future<void>> workers;
  const unsigned n = std::max(1u, std::min<unsigned>(std::thread::hardware_concurrency(), unsigned(which.size())));
  for (unsigned w = 0; w < n; ++w)
    workers.push_back(std::async(std::launch::async, [&] {
      for (size_t i; (i = next++) < which.size();) {
        const Texture& t = scene.textures.at(which[i]);
        use(i, loadImage(t.path.is_absolute() ? t.path : scene.baseDir / t.path, decodeChannels(t)));
      }
    }));
  for (auto& w : workers) w.get();  // rethrows the first error
}

bool alphaTested(const Mesh& mesh, const Material& material) {
  return !mesh.texcoords.empty() && material.texture(TextureSlot::AlphaMask) != kNoTexture &&
         (material.flags & (kMaterialAlphaMasked | kMaterialDoubleSided));
}

}  // namespace rtr
