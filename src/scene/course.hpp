#pragma once
// The course's baked mesh format (.comp5892mesh, variant default-a12), docs/formats.md.
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "scene/scene.hpp"

namespace rtr {

// Fallback textures that the course format needs where a material has no map (docs/formats.md).
// Readers map textures with these file names back to "no texture" (the factor defaults then apply).
constexpr std::string_view kFallbackBaseColor = "rtr-fallback-basecolor.png";  // RGBA ones
constexpr std::string_view kFallbackOne = "rtr-fallback-one.png";              // grey one: roughness, metalness
constexpr std::string_view kFallbackEmissive = "rtr-fallback-emissive.png";    // RGBA black, alpha one
bool isFallbackTexture(const std::filesystem::path& path);

// Bytes of the file. Every material must already carry its fallbacks: only alphaMask and normalMap may be
// absent. Texture paths are written as given (generic form). Meshes without texcoords get zeros.
std::string encodeCourseMesh(const Scene& scene);

// Parses and validates; fallback textures become kNoTexture. `file` labels errors.
// Materials are named "material<i>" (the format stores no names or factors).
Scene decodeCourseMesh(std::span<const uint8_t> bytes, const std::string& file);
Scene loadCourseMesh(const std::filesystem::path& file);

}  // namespace rtr
