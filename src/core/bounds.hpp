#pragma once
#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/common.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace rtr {

// The largest coordinate a scene may hold, refused by every reader with the file and the place: the
// cube of a difference of two coordinates (what intersection tests and meshoptimizer's cluster cones
// compute) must stay below float's 3.4e38. Non-finite coordinates fail this test too.
constexpr float kMaxCoordinate = 1e12f;
inline bool coordinateOk(const glm::vec3& p) {
  return std::abs(p.x) <= kMaxCoordinate && std::abs(p.y) <= kMaxCoordinate && std::abs(p.z) <= kMaxCoordinate;
}

struct Bounds {
  glm::vec3 min{std::numeric_limits<float>::infinity()};
  glm::vec3 max{-std::numeric_limits<float>::infinity()};

  void extend(const glm::vec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  void extend(const Bounds& b) {
    min = glm::min(min, b.min);
    max = glm::max(max, b.max);
  }
  bool empty() const { return !(min.x <= max.x && min.y <= max.y && min.z <= max.z); }
  glm::vec3 center() const { return (min + max) * 0.5f; }
  glm::vec3 extent() const { return max - min; }
};

// The box around `b`'s eight corners moved by `m`.
inline Bounds transformed(const Bounds& b, const glm::mat4& m) {
  if (b.empty()) return b;
  Bounds out;
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 p{i & 1 ? b.max.x : b.min.x, i & 2 ? b.max.y : b.min.y, i & 4 ? b.max.z : b.min.z};
    out.extend(glm::vec3(m * glm::vec4(p, 1.0f)));
  }
  return out;
}

}  // namespace rtr
