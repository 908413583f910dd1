#pragma once
// glTF 2.0 (.gltf with external, data-URI or GLB buffers; .glb) -> Scene. docs/gltf.md says what is
// read and what is not. Meshes are stored once per primitive and placed by Scene::instances.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "scene/load.hpp"
#include "scene/scene.hpp"

namespace rtr {

// Throws rtr::Error "FILE: /json/path: what is wrong".
Scene loadGltf(const std::filesystem::path& file, const LoadOptions& options = {});

// The same from memory (tests, fuzzing): `name` names it in messages, relative URIs resolve against
// `baseDir`. JSON or GLB, told apart by the GLB magic.
Scene parseGltf(std::span<const uint8_t> bytes, const std::string& name, const std::filesystem::path& baseDir,
                const LoadOptions& options = {});

}  // namespace rtr
