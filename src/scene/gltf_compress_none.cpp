// Until the decoders of src/scene/gltf_compress.cpp (branch gltf-store) are merged: compressed glTF
// geometry is refused with this message. Deleted when gltf_compress.cpp arrives.
#include "core/error.hpp"
#include "scene/gltf_compress.hpp"

namespace rtr::gltf {

void decodeMeshopt(std::span<const uint8_t>, size_t, size_t, std::string_view, std::string_view, std::span<uint8_t>) {
  throw Error("EXT_meshopt_compression is not decoded by this build");
}

DracoMesh decodeDraco(std::span<const uint8_t>, const std::vector<std::pair<std::string, int>>&) {
  throw Error("KHR_draco_mesh_compression is not decoded by this build");
}

}  // namespace rtr::gltf
