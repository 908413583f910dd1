#pragma once
// MTL parsing into rtr::Material, with texture file names kept per slot until the scene assigns ids.
#include <array>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "scene/scene.hpp"

namespace rtr {

struct MtlMaterial {
  Material material;
  std::array<std::string, kTextureSlotCount> maps;  // texture file per slot, as written (empty: none)
};

// Flags that follow from a material's name (docs/formats.md: ".DoubleSided" suffix, "light" in the name).
uint32_t flagsFromName(std::string_view name);

// Parses MTL text; `file` labels errors ("file:line: what"). Unknown keys go to `warn`.
std::vector<MtlMaterial> parseMtl(std::string_view text, const std::string& file,
                                  const std::function<void(const std::string&)>& warn);

// The PBR roughness for a classic MTL's Ns when it gives no Pr: the shared BRDF's Beckmann alpha (the
// roughness squared) becomes sqrt(2 / (Ns + 2)), the usual Phong-exponent-to-Beckmann match.
float roughnessFromNs(float ns);

// The slot conventions of the course format (docs/formats.md): colour space and channel count.
struct SlotFormat {
  bool srgb;
  uint8_t channels;
};
SlotFormat slotFormat(TextureSlot slot);

}  // namespace rtr
