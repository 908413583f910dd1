#pragma once
// Our baked format (.rtrscene): versioned, scalar factors instead of fallback textures, 16-bit indices where
// a mesh allows, 16-byte aligned arrays, a checksum over the payload. Byte table: docs/rtrscene-format.md.
#include <filesystem>
#include <span>
#include <string>

#include "scene/scene.hpp"

namespace rtr {

constexpr uint32_t kRtrSceneVersion = 3;  // 2 added lights, 3 clusters; versions 1 and 2 still load

// `version` below the current one writes an older layout (lights need 2, clusters 3), for tests of the reader.
std::string encodeRtrScene(const Scene& scene, uint32_t version = kRtrSceneVersion);
// Validates everything (sizes, counts, strings, indices, texture ids, finite values, checksum).
Scene decodeRtrScene(std::span<const uint8_t> bytes, const std::string& file);
Scene loadRtrScene(const std::filesystem::path& file);

}  // namespace rtr
