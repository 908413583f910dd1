#include "trace/intersect.hpp"

#include <cmath>
#include <utility>

#include <glm/geometric.hpp>

namespace rtr::trace {

float intersectHalfPlane(const Ray& r, const Triangle& tri, float& b1, float& b2) {
  const glm::vec3 n = glm::cross(tri.v1 - tri.v0, tri.v2 - tri.v0);
  const float denom = glm::dot(n, r.direction);
  if (denom == 0.0f) return -1.0f;  // parallel ray or zero-area triangle
  const float t = glm::dot(n, tri.v0 - r.origin) / denom;
  if (!(t > 0.0f && t < r.tMax)) return -1.0f;  // also rejects NaN
  const glm::vec3 p = r.origin + t * r.direction;
  // Inside when p lies on the inner side of all three edges (the brief's half-plane test).
  const float e0 = glm::dot(glm::cross(tri.v2 - tri.v1, p - tri.v1), n);  // opposite v0
  const float e1 = glm::dot(glm::cross(tri.v0 - tri.v2, p - tri.v2), n);  // opposite v1
  const float e2 = glm::dot(glm::cross(tri.v1 - tri.v0, p - tri.v0), n);  // opposite v2
  if (!(e0 >= 0.0f && e1 >= 0.0f && e2 >= 0.0f)) return -1.0f;
  const float nn = glm::dot(n, n);
  b1 = e1 / nn;
  b2 = e2 / nn;
  return t;
}

float intersectMollerTrumbore(const Ray& r, const Triangle& tri, float& b1, float& b2) {
  const glm::vec3 e1 = tri.v1 - tri.v0, e2 = tri.v2 - tri.v0;
  const glm::vec3 p = glm::cross(r.direction, e2);
  const float det = glm::dot(e1, p);
  if (det == 0.0f) return -1.0f;
  const float inv = 1.0f / det;
  const glm::vec3 s = r.origin - tri.v0;
  const float u = glm::dot(s, p) * inv;
  if (!(u >= 0.0f && u <= 1.0f)) return -1.0f;
  const glm::vec3 q = glm::cross(s, e1);
  const float v = glm::dot(r.direction, q) * inv;
  if (!(v >= 0.0f && u + v <= 1.0f)) return -1.0f;
  const float t = glm::dot(e2, q) * inv;
  if (!(t > 0.0f && t < r.tMax)) return -1.0f;
  b1 = u;
  b2 = v;
  return t;
}

WatertightRay::WatertightRay(const Ray& r) : origin(r.origin), tMax(r.tMax) {
  const glm::vec3 a = glm::abs(r.direction);
  kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
  kx = (kz + 1) % 3;
  ky = (kx + 1) % 3;
  if (r.direction[kz] < 0.0f) std::swap(kx, ky);  // keep the winding, so the sign of det means facing
  // One division; the BVH traversal (bvh_traverse.inl) repeats exactly these operations.
  sz = 1.0f / r.direction[kz];
  sx = r.direction[kx] * sz;
  sy = r.direction[ky] * sz;
}

float intersectWatertight(const WatertightRay& r, const Triangle& tri, float& b1, float& b2) {
  const glm::vec3 A = tri.v0 - r.origin, B = tri.v1 - r.origin, C = tri.v2 - r.origin;
  const float ax = A[r.kx] - r.sx * A[r.kz], ay = A[r.ky] - r.sy * A[r.kz];
  const float bx = B[r.kx] - r.sx * B[r.kz], by = B[r.ky] - r.sy * B[r.kz];
  const float cx = C[r.kx] - r.sx * C[r.kz], cy = C[r.ky] - r.sy * C[r.kz];
  float u = cx * by - cy * bx, v = ax * cy - ay * cx, w = bx * ay - by * ax;
  if (u == 0.0f || v == 0.0f || w == 0.0f) {
    // On an edge in float: decide in double, where the products of floats are exact.
    u = float(double(cx) * double(by) - double(cy) * double(bx));
    v = float(double(ax) * double(cy) - double(ay) * double(cx));
    w = float(double(bx) * double(ay) - double(by) * double(ax));
  }
  const bool inside = (u >= 0.0f && v >= 0.0f && w >= 0.0f) || (u <= 0.0f && v <= 0.0f && w <= 0.0f);
  if (!inside) return -1.0f;
  const float det = u + v + w;
  if (det == 0.0f) return -1.0f;  // degenerate, or the ray grazes the triangle's plane
  if (u == 0.0f || v == 0.0f || w == 0.0f) {
    // Exactly on an edge (or a vertex): a top-left fill rule in the sheared plane gives the point to
    // exactly one of the triangles sharing that edge, whatever their winding.
    const float s = det > 0.0f ? 1.0f : -1.0f;
    auto owns = [s](float x0, float y0, float x1, float y1) {
      const float ex = (x1 - x0) * s, ey = (y1 - y0) * s;
      return ey > 0.0f || (ey == 0.0f && ex > 0.0f);
    };
    if (u == 0.0f && !owns(bx, by, cx, cy)) return -1.0f;
    if (v == 0.0f && !owns(cx, cy, ax, ay)) return -1.0f;
    if (w == 0.0f && !owns(ax, ay, bx, by)) return -1.0f;
  }
  const float az = r.sz * A[r.kz], bz = r.sz * B[r.kz], cz = r.sz * C[r.kz];
  const float T = u * az + v * bz + w * cz;
  // t = T/det must lie in (0, tMax): compare without dividing, with det's sign.
  const bool ok = det > 0.0f ? (T > 0.0f && T < r.tMax * det) : (T < 0.0f && T > r.tMax * det);
  if (!ok) return -1.0f;
  const float inv = 1.0f / det;
  b1 = v * inv;
  b2 = w * inv;
  const float t = T * inv;
  return t > 0.0f ? t : -1.0f;  // T/det can underflow to 0 for t near the origin
}

float intersect(IntersectMethod m, const Ray& r, const Triangle& tri, float& b1, float& b2) {
  switch (m) {
    case IntersectMethod::HalfPlane: return intersectHalfPlane(r, tri, b1, b2);
    case IntersectMethod::MollerTrumbore: return intersectMollerTrumbore(r, tri, b1, b2);
    case IntersectMethod::Watertight: break;
  }
  return intersectWatertight(r, tri, b1, b2);
}

glm::vec3 barycentric(const Triangle& tri, const glm::vec3& p) {
  const glm::vec3 n = glm::cross(tri.v1 - tri.v0, tri.v2 - tri.v0);
  const float nn = glm::dot(n, n);
  if (!(nn > 0.0f)) return {1.0f, 0.0f, 0.0f};
  const float alpha = glm::dot(glm::cross(tri.v2 - tri.v1, p - tri.v1), n) / nn;
  const float beta = glm::dot(glm::cross(tri.v0 - tri.v2, p - tri.v2), n) / nn;
  return {alpha, beta, 1.0f - alpha - beta};
}

}  // namespace rtr::trace
