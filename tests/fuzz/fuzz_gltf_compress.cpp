// Fuzzes the glTF geometry decoders (scene/gltf_compress): byte 0 picks the meshopt mode, filter and
// stride, byte 1 the element count, the rest is the compressed data, which also goes to the draco decoder.
// Either decoder may refuse (rtr::Error); what it returns must be usable as the glTF reader uses it.
// Draco only with RTR_FUZZ_DRACO=1: the library allocates by the counts a stream declares (5.2 GB and more
// from 159 bytes: docs/fuzzing.md, finding 11, open), which stops every short run on out-of-memory.
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "check.hpp"
#include "scene/gltf_compress.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rtr;
  if (size < 2) return 0;
  static const char* const modes[] = {"ATTRIBUTES", "TRIANGLES", "INDICES"};
  static const char* const filters[] = {"NONE", "OCTAHEDRAL", "QUATERNION", "EXPONENTIAL"};
  static const size_t strides[] = {2, 4, 8, 12, 16, 20, 32, 64};
  const uint8_t pick = data[0];
  const size_t count = size_t(data[1]) * 3 + 3, stride = strides[(pick / 12) % 8];
  const std::span<const uint8_t> src(data + 2, size - 2);
  std::vector<uint8_t> out(count * stride);
  try {
    gltf::decodeMeshopt(src, count, stride, modes[pick % 3], filters[(pick / 3) % 4], out);
  } catch (const Error&) {}
  static const bool draco = std::getenv("RTR_FUZZ_DRACO") != nullptr;
  if (!draco) return 0;
  try {
    const gltf::DracoMesh m = gltf::decodeDraco(src, {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}});
    fuzz::require(m.indices.size() % 3 == 0, "draco: index count not a multiple of 3");
    for (uint32_t i : m.indices) fuzz::require(i < m.vertexCount, "draco: index out of range");
    for (const gltf::DracoAttribute& a : m.attributes)
      fuzz::require(a.values.size() == size_t(m.vertexCount) * size_t(a.components), "draco: attribute size");
  } catch (const Error&) {}
  return 0;
}
