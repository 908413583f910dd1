// Fuzzes the baked-format loaders: any input must give a Scene or an rtr::Error, never a crash.
// The first byte picks the format so one corpus covers both.
#include <cstdint>
#include <span>

#include "core/error.hpp"
#include "scene/course.hpp"
#include "scene/rtrscene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  std::span<const uint8_t> bytes(data + 1, size - 1);
  try {
    rtr::Scene s = (data[0] & 1) ? rtr::decodeRtrScene(bytes, "fuzz.rtrscene") : rtr::decodeCourseMesh(bytes, "fuzz.comp5892mesh");
    // A loaded scene must be safe to walk.
    for (const rtr::Mesh& m : s.meshes)
      for (uint32_t i : m.indices)
        if (i >= m.positions.size()) __builtin_trap();
  } catch (const rtr::Error&) {
  }
  return 0;
}
