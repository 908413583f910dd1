#pragma once
// Random numbers for the tracer's Monte Carlo: a PCG32 generator (O'Neill 2014: a 64-bit LCG whose
// output is permuted by a xorshift and a data-dependent rotation) seeded per pixel, so an image is the
// same for every thread count and tile size.
#include <cstdint>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace rtr::trace {

class Rng {
 public:
  explicit Rng(uint64_t seed = 0) {
    next();
    state_ += seed;
    next();
  }
  // The generator of pixel (x, y): its own stream, the same whichever thread traces it.
  static Rng forPixel(uint32_t x, uint32_t y) { return Rng(mix(uint64_t(y) << 32 | x)); }

  uint32_t next() {
    const uint64_t s = state_;
    state_ = s * 6364136223846793005ull + 1442695040888963407ull;
    const uint32_t xs = uint32_t(((s >> 18) ^ s) >> 27), rot = uint32_t(s >> 59);
    return (xs >> rot) | (xs << ((32u - rot) & 31u));
  }
  // Uniform in [0, 1): the top 24 bits, so the float is exact and never rounds up to 1.
  float uniform() { return float(next() >> 8) * 0x1p-24f; }
  glm::vec2 uniform2() {
    const float a = uniform();
    return {a, uniform()};
  }
  glm::vec3 uniform3() {
    const float a = uniform(), b = uniform();
    return {a, b, uniform()};
  }

 private:
  // A 64-bit finaliser (splitmix64's): neighbouring pixels' seeds share no visible pattern.
  static uint64_t mix(uint64_t z) {
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  uint64_t state_ = 0;
};

}  // namespace rtr::trace
