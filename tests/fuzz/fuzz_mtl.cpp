// Fuzzes the MTL parser alone: materials, or an error naming the file.
#include <cstdint>
#include <string_view>

#include "check.hpp"
#include "scene/mtl.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    for (const rtr::MtlMaterial& m :
         rtr::parseMtl({reinterpret_cast<const char*>(data), size}, "fuzz.mtl", [](const std::string&) {}))
      rtr::fuzz::require(
          (m.material.flags & ~uint32_t(rtr::kMaterialAlphaMasked | rtr::kMaterialDoubleSided | rtr::kMaterialLight)) == 0,
          "unknown material flags");
  } catch (const rtr::Error& e) { rtr::fuzz::requireNamesFile(e, "fuzz.mtl"); }
  return 0;
}
