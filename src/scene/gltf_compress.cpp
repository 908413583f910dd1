#include "scene/gltf_compress.hpp"

#include <memory>
#include <new>

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>
#include <meshoptimizer.h>

#include "core/error.hpp"

namespace rtr::gltf {
namespace {

std::string str(std::string_view s) { return std::string(s); }

}  // namespace

void decodeMeshopt(std::span<const uint8_t> src, size_t count, size_t byteStride, std::string_view mode, std::string_view filter,
                   std::span<uint8_t> out) {
  // The library asserts what it expects instead of reporting it: each of its preconditions is checked here.
  if (byteStride == 0 || count > out.size() / byteStride || count * byteStride != out.size())
    throw Error("meshopt: count " + std::to_string(count) + " × byteStride " + std::to_string(byteStride) + " is not the " +
                std::to_string(out.size()) + " bytes of the bufferView");
  const bool attributes = mode == "ATTRIBUTES";
  if (!attributes && mode != "TRIANGLES" && mode != "INDICES") throw Error("meshopt: unknown mode '" + str(mode) + "'");
  if (filter != "NONE" && !attributes)
    throw Error("meshopt: filter " + str(filter) + " with mode " + str(mode) + " (filters apply to ATTRIBUTES only)");
  int rc = 0;
  if (attributes) {
    if (byteStride % 4 != 0 || byteStride > 256)
      throw Error("meshopt: ATTRIBUTES byteStride " + std::to_string(byteStride) + " is not a multiple of 4 up to 256");
    const bool oct = filter == "OCTAHEDRAL", quat = filter == "QUATERNION", exp = filter == "EXPONENTIAL";
    if (!oct && !quat && !exp && filter != "NONE") throw Error("meshopt: unknown filter '" + str(filter) + "'");
    if ((oct && byteStride != 4 && byteStride != 8) || (quat && byteStride != 8))
      throw Error("meshopt: filter " + str(filter) + " with byteStride " + std::to_string(byteStride) +
                  (oct ? " (must be 4 or 8)" : " (must be 8)"));
    rc = meshopt_decodeVertexBuffer(out.data(), count, byteStride, src.data(), src.size());
    if (rc == 0 && oct) meshopt_decodeFilterOct(out.data(), count, byteStride);
    if (rc == 0 && quat) meshopt_decodeFilterQuat(out.data(), count, byteStride);
    if (rc == 0 && exp) meshopt_decodeFilterExp(out.data(), count, byteStride);
  } else {
    if (byteStride != 2 && byteStride != 4)
      throw Error("meshopt: " + str(mode) + " byteStride " + std::to_string(byteStride) + " is neither 2 nor 4");
    if (mode == "TRIANGLES" && count % 3 != 0)
      throw Error("meshopt: TRIANGLES count " + std::to_string(count) + " is not a multiple of 3");
    rc = mode == "TRIANGLES" ? meshopt_decodeIndexBuffer(out.data(), count, byteStride, src.data(), src.size())
                             : meshopt_decodeIndexSequence(out.data(), count, byteStride, src.data(), src.size());
  }
  if (rc != 0)
    throw Error("meshopt: the " + std::to_string(src.size()) + " compressed bytes do not decode as " + str(mode) + " (error " +
                std::to_string(rc) + ")");
}

DracoMesh decodeDraco(std::span<const uint8_t> src, const std::vector<std::pair<std::string, int>>& attributes) {
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(src.data()), src.size());
  std::unique_ptr<draco::Mesh> mesh;
  try {
    draco::Decoder decoder;
    auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
    if (!decoded.ok()) throw Error("draco: " + decoded.status().error_msg_string());
    mesh = std::move(decoded).value();
  } catch (const std::bad_alloc&) {
    throw Error("draco: the data asks for more memory than there is");
  } catch (const std::length_error&) { throw Error("draco: the data asks for more memory than there is"); }
  if (!mesh) throw Error("draco: not a triangle mesh");
  DracoMesh out;
  out.vertexCount = mesh->num_points();
  const uint32_t faces = mesh->num_faces();
  out.indices.reserve(size_t(faces) * 3);
  for (uint32_t f = 0; f < faces; ++f)
    for (draco::PointIndex p : mesh->face(draco::FaceIndex(f))) {
      if (p.value() >= out.vertexCount)
        throw Error("draco: face " + std::to_string(f) + " names point " + std::to_string(p.value()) + " of " +
                    std::to_string(out.vertexCount));
      out.indices.push_back(p.value());
    }
  for (const auto& [name, id] : attributes) {
    const draco::PointAttribute* a = id >= 0 ? mesh->GetAttributeByUniqueId(uint32_t(id)) : nullptr;
    if (!a) throw Error("draco: attribute " + name + " names id " + std::to_string(id) + ", which the data does not have");
    // glTF's component types only (a bool attribute would be read as bools whatever its bytes are).
    switch (a->data_type()) {
      case draco::DT_INT8:
      case draco::DT_UINT8:
      case draco::DT_INT16:
      case draco::DT_UINT16:
      case draco::DT_INT32:
      case draco::DT_UINT32:
      case draco::DT_FLOAT32: break;
      default: throw Error("draco: attribute " + name + " has a data type glTF does not use");
    }
    const int n = a->num_components();
    if (n < 1 || n > 4) throw Error("draco: attribute " + name + " has " + std::to_string(n) + " components");
    if (!a->is_mapping_identity() && a->indices_map_size() < out.vertexCount)
      throw Error("draco: attribute " + name + " maps fewer points than the mesh has");
    DracoAttribute& d = out.attributes.emplace_back();
    d.name = name;
    d.components = n;
    d.values.resize(size_t(out.vertexCount) * size_t(n));
    for (uint32_t p = 0; p < out.vertexCount; ++p) {
      const draco::AttributeValueIndex v = a->mapped_index(draco::PointIndex(p));
      if (v.value() >= a->size() || !a->ConvertValue<float>(v, int8_t(n), &d.values[size_t(p) * size_t(n)]))
        throw Error("draco: attribute " + name + ": point " + std::to_string(p) + " has no readable value");
    }
  }
  return out;
}

}  // namespace rtr::gltf
