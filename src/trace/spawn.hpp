#pragma once
// Starting points of secondary rays. The hit point is rebuilt from the barycentrics (not o + t·d, whose
// error grows with t) and pushed off the surface along the geometric normal by a fixed number of ulps of
// each coordinate (Wächter and Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray
// Tracing Gems ch. 6): the offset scales with the coordinates' magnitude, so no scene-scale epsilon.
#include <bit>
#include <cmath>
#include <cstdint>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "trace/ray.hpp"

namespace rtr::trace {

// p: point on the surface; n: unit geometric normal on the side the new ray leaves from.
inline glm::vec3 offsetRayOrigin(const glm::vec3& p, const glm::vec3& n) {
  constexpr float kNearOrigin = 1.0f / 32.0f;  // below this, ulps are too small: use a fixed step
  constexpr float kFixedStep = 1.0f / 65536.0f;
  constexpr float kUlps = 256.0f;
  glm::vec3 out;
  for (int a = 0; a < 3; ++a) {
    const int32_t steps = int32_t(kUlps * n[a]);
    const int32_t bits = std::bit_cast<int32_t>(p[a]) + (p[a] < 0.0f ? -steps : steps);
    out[a] = std::fabs(p[a]) < kNearOrigin ? p[a] + kFixedStep * n[a] : std::bit_cast<float>(bits);
  }
  return out;
}

// A ray leaving surface point p (unit geometric normal ng, either orientation) in direction dir.
inline Ray spawnRay(const glm::vec3& p, const glm::vec3& ng, const glm::vec3& dir, float tMax = INFINITY) {
  const glm::vec3 side = glm::dot(ng, dir) >= 0.0f ? ng : -ng;
  return {offsetRayOrigin(p, side), dir, tMax};
}

// The brief's reflectRay: mirror direction d about unit normal n, leaving from hit point p.
inline Ray reflectRay(const Ray& r, const glm::vec3& n, const glm::vec3& p, const glm::vec3& ng) {
  const glm::vec3 d = r.direction - 2.0f * glm::dot(r.direction, n) * n;
  return spawnRay(p, ng, d);
}

}  // namespace rtr::trace
