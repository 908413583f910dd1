#pragma once
// Single ray against single triangle. Each routine returns t (> 0 and < ray.tMax) of the hit, or a
// negative number for "no hit" (the brief's convention), and writes the barycentric weights of
// vertices 1 and 2 on a hit. None of them produces NaN for degenerate triangles or parallel rays.
#include <glm/vec3.hpp>

#include "trace/ray.hpp"

namespace rtr::trace {

struct Triangle {
  glm::vec3 v0, v1, v2;
};

// The brief's Task 3: intersect the supporting plane, then test the point against the three edges'
// half-planes (sign of (e_i × (p − v_i)) · n). Not watertight: rays through shared edges can slip through.
float intersectHalfPlane(const Ray& r, const Triangle& tri, float& b1, float& b2);

// Möller and Trumbore 1997, for the speed/error comparison only.
float intersectMollerTrumbore(const Ray& r, const Triangle& tri, float& b1, float& b2);

// Per-ray set-up of the watertight test: the axis permutation and shear that make the ray +z.
struct WatertightRay {
  glm::vec3 origin;
  int kx, ky, kz;
  float sx, sy, sz;
  float tMax;
  explicit WatertightRay(const Ray& r);
};

// Woop, Benthin, Wald, "Watertight Ray/Triangle Intersection", JCGT 2013: translate to the ray origin,
// permute and shear so the ray runs along +z, then 2D edge functions; when an edge function is exactly
// zero it is recomputed in double precision, so an edge shared by two triangles is owned consistently.
float intersectWatertight(const WatertightRay& r, const Triangle& tri, float& b1, float& b2);
inline float intersectWatertight(const Ray& r, const Triangle& tri, float& b1, float& b2) {
  return intersectWatertight(WatertightRay(r), tri, b1, b2);
}

float intersect(IntersectMethod m, const Ray& r, const Triangle& tri, float& b1, float& b2);

// The brief's Task 4 ("baricentric"): barycentric weights (alpha, beta, gamma) of point p in the
// triangle's plane, from ratios of signed sub-triangle areas. Zero-area triangles give (1,0,0).
glm::vec3 barycentric(const Triangle& tri, const glm::vec3& p);

}  // namespace rtr::trace
