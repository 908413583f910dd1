#pragma once
#include <algorithm>
#include <limits>

#include <glm/vec3.hpp>
#include <glm/common.hpp>

namespace rtr {

struct Bounds {
  glm::vec3 min{std::numeric_limits<float>::infinity()};
  glm::vec3 max{-std::numeric_limits<float>::infinity()};

  void extend(const glm::vec3& p) { min = glm::min(min, p); max = glm::max(max, p); }
  void extend(const Bounds& b) { min = glm::min(min, b.min); max = glm::max(max, b.max); }
  bool empty() const { return !(min.x <= max.x && min.y <= max.y && min.z <= max.z); }
  glm::vec3 center() const { return (min + max) * 0.5f; }
  glm::vec3 extent() const { return max - min; }
};

}  // namespace rtr
