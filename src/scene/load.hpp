#pragma once
// One entry point for every scene file the project reads; the extension picks the format.
#include <filesystem>

#include "scene/scene.hpp"

namespace rtr {

// .obj / .obj.zst / .obj-zstd (with their MTL), .comp5892mesh, .rtrscene.
// Throws rtr::Error naming the file and the place of the fault.
Scene loadScene(const std::filesystem::path& file);

}  // namespace rtr
