// Fuzzes the .comp5892mesh decoder: any input gives a usable scene or an error naming the file.
#include <cstdint>

#include "check.hpp"
#include "scene/course.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    rtr::fuzz::checkScene(rtr::decodeCourseMesh({data, size}, "fuzz.comp5892mesh"));
  } catch (const rtr::Error& e) { rtr::fuzz::requireNamesFile(e, "fuzz.comp5892mesh"); }
  return 0;
}
