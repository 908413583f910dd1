#pragma once
// OBJ + MTL to rtr::Scene: streaming parse (plain or zstd), polygons triangulated (convex: fan; concave:
// ear clipping), one mesh per (object/group x material), vertex welding within 1e-5, area-weighted
// normals where missing. docs/obj-mtl.md says what is read, what is lenient and what is refused.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "scene/load.hpp"
#include "scene/scene.hpp"
#include "scene/stream.hpp"

namespace rtr {

// LoadOptions (mtl, warn, note) plus what only the OBJ reader takes.
struct ObjOptions : LoadOptions {
  // Called now and then while reading with (bytes consumed from the file, file size).
  std::function<void(uint64_t, uint64_t)> progress;
  // Called now and then while welding with the fraction of the corners welded.
  std::function<void(double)> weldProgress;
  // Called on the reading thread as each step of the parse and the weld begins, with its name (rtr-bake
  // --profile counts the cores each keeps busy).
  std::function<void(const char*)> step;
  unsigned threads = 0;   // parse and weld workers; 0 = all cores
  size_t pieceBytes = 0;  // text parsed as one piece (0: 256 KiB); tests force tiny pieces to put boundaries everywhere
};

struct ObjStats {
  uint64_t fileBytes = 0;                            // bytes of the input file (compressed when zstd)
  uint64_t textBytes = 0;                            // bytes of OBJ text parsed
  size_t positions = 0, normals = 0, texcoords = 0;  // v / vn / vt records
  size_t faces = 0;
  size_t triangles = 0;           // kept triangles
  size_t degenerateSkipped = 0;   // triangles with repeated corners or zero area
  size_t verticesBeforeWeld = 0;  // triangle corners (the soup)
  size_t verticesAfterWeld = 0;
  size_t warnings = 0;  // all of them, also those not passed on to the sink
  double parseSeconds = 0, weldSeconds = 0;
  double parseCpuSeconds = 0, weldCpuSeconds = 0;  // the process's CPU time (all threads): against the wall time,
                                                   // how many cores the phase kept busy
  double textWaitSeconds = 0;  // of parseSeconds: waiting for text (read, decompressed) that the parse did not hide
};

// Reads `file` (.obj, .obj.zst, .obj-zstd) and its MTL: options.mtl when given (an error when absent),
// else the files named by `mtllib` beside it (a warning when absent), else NAME.mtl beside it if present.
// Throws rtr::Error naming the file and line (or byte offset for zstd faults).
Scene loadObj(const std::filesystem::path& file, const ObjOptions& options = {}, ObjStats* stats = nullptr);

// The same parser over any byte source; `name` labels errors. `readMtl(name)` returns the text of an MTL:
// one named by an `mtllib` line, `options.mtl` (as given), or `besideMtl`; std::nullopt when it does not
// exist (throwing rtr::Error when it cannot be read). `besideMtl` (may be empty) is read at the first
// `usemtl` when no `mtllib` came before. Used by loadObj, tests and fuzzing.
using MtlReader = std::function<std::optional<std::string>(const std::string& mtlName)>;
Scene parseObj(ByteSource& source, const std::string& name, const MtlReader& readMtl, const ObjOptions& options = {},
               ObjStats* stats = nullptr, const std::string& besideMtl = {});

}  // namespace rtr
