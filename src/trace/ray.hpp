#pragma once
// Rays and hits of the CPU ray tracer. World space, right-handed, y up (core/camera.hpp).
#include <array>
#include <cstdint>
#include <limits>

#include <glm/vec3.hpp>
#include <xmmintrin.h>

#include "core/enum_names.hpp"

namespace rtr::trace {

struct Ray {
  glm::vec3 origin{0.0f};
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // need not be unit length; t is measured in its units
  float tMax = std::numeric_limits<float>::infinity();
};

// Denormals flushed to zero while alive (they only slow tracing down); the thread's mode restored after.
struct FlushDenormals {
  unsigned saved = _mm_getcsr();
  FlushDenormals() { _mm_setcsr(saved | 0x8040u); }  // FTZ | DAZ
  ~FlushDenormals() { _mm_setcsr(saved); }
  FlushDenormals(const FlushDenormals&) = delete;
  FlushDenormals& operator=(const FlushDenormals&) = delete;
};

constexpr uint32_t kNoHit = 0xFFFFFFFFu;

// Closest hit: t along the ray, barycentric weights b1, b2 of vertices 1 and 2 (b0 = 1 - b1 - b2),
// the index of the triangle in the tracer's triangle list, and in a scene with instances which one.
struct Hit {
  float t = std::numeric_limits<float>::infinity();
  float b1 = 0.0f, b2 = 0.0f;
  uint32_t prim = kNoHit;
  uint32_t instance = 0;  // Scene::instances index (InstanceBvh); 0 without instances
  bool hit() const { return prim != kNoHit; }
};

// Which ray-triangle test to use. HalfPlane is the brief's (plane, then three edge half-plane tests);
// Watertight is Woop, Benthin and Wald 2013; MollerTrumbore is there to be measured against.
enum class IntersectMethod { HalfPlane, Watertight, MollerTrumbore };
constexpr std::array<EnumName<IntersectMethod>, 3> enumNames(IntersectMethod) {
  return {{{IntersectMethod::HalfPlane, "halfplane"},
           {IntersectMethod::Watertight, "watertight"},
           {IntersectMethod::MollerTrumbore, "moller"}}};
}

}  // namespace rtr::trace
