#pragma once
// The two glTF geometry compressions, decoded from untrusted bytes: every size is checked before a
// decoder runs, and a decoder's failure is an rtr::Error saying what is wrong (the glTF reader adds the
// file and the JSON path). Specs: EXT_meshopt_compression and KHR_draco_mesh_compression (docs/gltf.md).
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace rtr::gltf {

// EXT_meshopt_compression: decodes one compressed bufferView (its extension object's fields) into `out`,
// which holds count * byteStride bytes. Throws rtr::Error with what is wrong (the caller adds file and path).
void decodeMeshopt(std::span<const uint8_t> src, size_t count, size_t byteStride, std::string_view mode, std::string_view filter,
                   std::span<uint8_t> out);

// KHR_draco_mesh_compression: decodes a primitive's draco bufferView. `attributes` maps glTF attribute
// names (POSITION, NORMAL, TEXCOORD_0, ...) to draco attribute ids. Values come out as floats, `components`
// per vertex; indices as a triangle list.
struct DracoAttribute {
  std::string name;
  int components = 0;
  std::vector<float> values;
};
struct DracoMesh {
  std::vector<uint32_t> indices;
  std::vector<DracoAttribute> attributes;
  uint32_t vertexCount = 0;
};
DracoMesh decodeDraco(std::span<const uint8_t> src, const std::vector<std::pair<std::string, int>>& attributes);

}  // namespace rtr::gltf
