#include <unordered_map>

#include "bake.hpp"
#include "core/error.hpp"
#include "scene/course.hpp"
#include "scene/mtl.hpp"

namespace rtr {

TexturePlan planTextures(const Scene& in, const std::string& sceneName, bool courseFallbacks) {
  TexturePlan plan;
  plan.scene.baseDir = in.baseDir;
  plan.scene.meshes = in.meshes;
  plan.scene.defaultView = in.defaultView;
  plan.scene.lights = in.lights;
  std::unordered_map<std::string, uint32_t> ids;           // destination path -> new id
  std::unordered_map<std::string, std::string> sourceOf;   // destination path -> source, to catch clashes
  const std::string folder = sceneName + "-tex/";

  auto idFor = [&](const std::string& rel, const std::filesystem::path& src, TextureSlot slot) {
    auto [it, added] = ids.try_emplace(rel, uint32_t(plan.scene.textures.size()));
    if (added) {
      const SlotFormat f = slotFormat(slot);
      plan.scene.textures.push_back({rel, f.srgb, f.channels});
      plan.sources.push_back(src);
      sourceOf[rel] = src.string();
    } else if (sourceOf[rel] != src.string()) {
      throw Error("textures '" + sourceOf[rel] + "' and '" + src.string() + "' would both be copied to '" + rel +
                  "'; rename one of them");
    }
    return it->second;
  };

  for (const Material& m : in.materials) {
    Material out = m;
    for (uint32_t s = 0; s < kTextureSlotCount; ++s) {
      const uint32_t id = m.textures[s];
      const TextureSlot slot = TextureSlot(s);
      if (id != kNoTexture) {
        if (id >= in.textures.size()) throw Error("material '" + m.name + "': texture id out of range");
        const Texture& t = in.textures[id];
        if (isFallbackTexture(t.path)) throw Error("texture file name '" + t.path.filename().string() + "' is reserved");
        const std::filesystem::path src = t.path.is_absolute() ? t.path : in.baseDir / t.path;
        out.textures[s] = idFor(folder + t.path.filename().string(), src, slot);
      } else if (courseFallbacks && slot != TextureSlot::AlphaMask && slot != TextureSlot::NormalMap) {
        std::string_view name = slot == TextureSlot::BaseColor ? kFallbackBaseColor
                                : slot == TextureSlot::Emissive ? kFallbackEmissive
                                                                : kFallbackOne;
        out.textures[s] = idFor(folder + std::string(name), {}, slot);
      }
    }
    plan.scene.materials.push_back(std::move(out));
  }
  return plan;
}

}  // namespace rtr
