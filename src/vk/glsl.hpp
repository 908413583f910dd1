#pragma once
// GLSL to SPIR-V at run time with the glslang library (rtr-reflect on .comp/.vert/.frag files, and
// shader hot reload). Same target as the build: Vulkan 1.3, SPIR-V 1.6.
#include <filesystem>
#include <vector>

#include "vk/reflect.hpp"

namespace rtr::vk {

// The stage comes from the extension, as for glslangValidator (.vert, .frag, .comp, .rgen, .rchit, .mesh,
// ...). A compile error is an rtr::Error whose message carries glslang's "file:line: message" lines.
SpirvModule compileGlsl(const std::filesystem::path& file, const std::vector<std::filesystem::path>& includeDirs = {});
bool isGlslPath(const std::filesystem::path& file);

}  // namespace rtr::vk
