#pragma once
// OBJ + MTL to rtr::Scene: streaming parse (plain or zstd), fan triangulation, one mesh per
// (object/group x material), vertex welding within 1e-5, area-weighted normals where missing.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

#include "scene/scene.hpp"
#include "scene/stream.hpp"

namespace rtr {

struct ObjOptions {
  // Non-fatal findings (unknown keys, unknown materials); default prints "warning: ..." to stderr.
  std::function<void(const std::string&)> warn;
  // Called now and then while reading with (bytes consumed from the file, file size).
  std::function<void(uint64_t, uint64_t)> progress;
  unsigned threads = 0;  // welding workers; 0 = hardware concurrency
};

struct ObjStats {
  uint64_t fileBytes = 0;         // bytes of the input file (compressed when zstd)
  uint64_t textBytes = 0;         // bytes of OBJ text parsed
  size_t positions = 0, normals = 0, texcoords = 0;  // v / vn / vt records
  size_t faces = 0;
  size_t triangles = 0;           // kept triangles
  size_t degenerateSkipped = 0;   // triangles with repeated corners or zero area
  size_t verticesBeforeWeld = 0;  // triangle corners (the soup)
  size_t verticesAfterWeld = 0;
  size_t warnings = 0;
  double parseSeconds = 0, weldSeconds = 0;
};

// Reads `file` (.obj, .obj.zst, .obj-zstd) and the MTL files it names from beside it.
// Throws rtr::Error naming the file and line (or byte offset for zstd faults).
Scene loadObj(const std::filesystem::path& file, const ObjOptions& options = {}, ObjStats* stats = nullptr);

// The same parser over any byte source. `readMtl(name)` returns the text of the MTL named by an
// `mtllib` line (throwing rtr::Error when it cannot); `name` labels errors. Used by tests and fuzzing.
using MtlReader = std::function<std::string(const std::string& mtlName)>;
Scene parseObj(ByteSource& source, const std::string& name, const MtlReader& readMtl,
               const ObjOptions& options = {}, ObjStats* stats = nullptr);

}  // namespace rtr
