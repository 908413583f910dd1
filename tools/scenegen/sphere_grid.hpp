#pragma once
// The glTF MetalRoughSpheres-like test scene: spheres of metallic (rows) × roughness (columns), the case
// that shows a metal-rough BRDF under an environment (docs/environment.md).
#include <filesystem>

namespace scenegen {

// Writes `file` (.gltf) and its buffer beside it (same name, .bin): an n × n grid of unit-spaced spheres
// of radius 0.42 in the z = 0 plane, centred on the origin; row r from the top has metallic r / (n - 1),
// column c from the left roughness c / (n - 1); base colour one light gold for all. Throws rtr::Error.
void writeSphereGrid(const std::filesystem::path& file, int n);

}  // namespace scenegen
