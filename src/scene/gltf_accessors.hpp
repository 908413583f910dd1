#pragma once
// glTF buffers, buffer views and accessors: every byte range bounds-checked with overflow-safe arithmetic
// before it is read, faults naming the file and the JSON path. Buffers are memory-mapped (external
// files) or used in place (a GLB's BIN chunk); only data URIs and compressed views are decoded to memory.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "scene/gltf_json.hpp"

namespace rtr {
class MappedFile;
}

namespace rtr::gltf {

// Decodes base64 (RFC 4648, padding optional); nullopt when a character is not base64.
std::optional<std::vector<uint8_t>> decodeBase64(std::string_view text);
// "data:[mime][;base64],..." split: the payload decoded, or an error at `where`.
std::vector<uint8_t> decodeDataUri(const Json& where, std::string_view uri);
// A relative URI reference as a path: %XX escapes decoded.
std::string uriToPath(std::string_view uri);

class Accessors {
 public:
  // `glbBin`: the GLB's BIN chunk (empty for .gltf), used for a buffer without uri.
  Accessors(const Json& root, std::filesystem::path baseDir, std::span<const uint8_t> glbBin, bool isGlb);
  ~Accessors();

  // The bytes of buffer view `view` (decoded when it is meshopt-compressed), checked against its buffer.
  std::span<const uint8_t> view(uint32_t view);
  size_t viewCount() const { return views_.size(); }
  size_t accessorCount() const { return accessors_.size(); }

  // Accessor facts, checked: component type and count against its view.
  struct Info {
    uint32_t count = 0;
    int components = 0;          // 1..4 (SCALAR..VEC4); matrices are not read
    uint32_t componentType = 0;  // 5120..5126
    bool normalized = false;
  };
  Info info(uint32_t accessor) const;
  Json json(uint32_t accessor) const { return accessors_[accessor]; }

  // Resolves (maps, decodes) every view accessor `a` reads, so that readFloats and readIndices of it
  // may then run on several threads at once: they only read what is resolved.
  void prepare(uint32_t accessor);
  // Reads accessor `a` as floats (normalized integers mapped to [0,1] / [-1,1], others converted) into
  // dst, `dstComponents` floats per element (extra components left as they are, missing ones not
  // written). `allowedComponents` lists the component counts the caller takes; dst holds count elements.
  void readFloats(uint32_t accessor, float* dst, int dstComponents, std::initializer_list<int> allowedComponents);
  // Reads a SCALAR integer accessor (indices) as uint32.
  void readIndices(uint32_t accessor, std::vector<uint32_t>& out);

 private:
  std::span<const uint8_t> buffer(uint32_t i);
  // The checked byte range of an accessor's elements: element i at data[i * stride].
  struct Range {
    std::span<const uint8_t> data;
    size_t stride = 0;
  };
  Range range(const Json& a, uint32_t viewIndex, uint64_t byteOffset, uint64_t count, size_t elemSize, bool viewStrideAllowed);
  template <class Write>
  void forEach(uint32_t accessor, const Info& info, Write&& write);

  Json root_;
  std::filesystem::path baseDir_;
  std::span<const uint8_t> glbBin_;
  bool isGlb_;
  std::vector<Json> buffersJ_, views_, accessors_;
  std::vector<std::optional<std::span<const uint8_t>>> buffers_;
  std::vector<std::unique_ptr<MappedFile>> mapped_;
  std::vector<std::vector<uint8_t>> owned_;                        // decoded data URIs
  std::vector<std::optional<std::vector<uint8_t>>> decodedViews_;  // meshopt
};

}  // namespace rtr::gltf
