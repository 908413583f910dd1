#pragma once
// The baseline bake the benchmark compares against: tinyobjloader parse, a std::unordered_map weld on
// exact vertex values, the same normal generation and the same .rtrscene encoder.
#include <filesystem>

#include "scene/scene.hpp"

namespace bench {
rtr::Scene baselineLoad(const std::filesystem::path& obj);
}
