#pragma once
// One entry point for every scene file the project reads; the extension picks the format.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "scene/scene.hpp"

namespace rtr {

struct LoadOptions {
  // OBJ only: read materials from this MTL instead of the OBJ's `mtllib` lines (the course's ray-tracer
  // framework is started as `program NAME.obj NAME.mtl`). Without it, an OBJ that has no `mtllib` line
  // uses NAME.mtl beside it when that file exists.
  std::optional<std::filesystem::path> mtl;
  // OBJ only: where a face has no normals, they are split at this angle between faces (degrees; 0 flat,
  // 180 smooth): --crease.
  float creaseDeg = 40.0f;
  // Non-fatal findings ("file:line: what"); at most 10 are passed on, then one line with the total.
  // Default: "warning: ..." on stderr.
  std::function<void(const std::string&)> warn;
  // What the loader chose on its own (the MTL it used, elements it skipped). Default: "note: ..." on stderr.
  std::function<void(const std::string&)> note;
};

// .obj / .obj.zst / .obj-zstd (with their MTL), .gltf / .glb (scene/gltf.hpp), .comp5892mesh, .rtrscene.
// Throws rtr::Error naming the file and the place of the fault.
Scene loadScene(const std::filesystem::path& file, const LoadOptions& options = {});

}  // namespace rtr
