#include "scene/triangulate.hpp"

#include <array>
#include <cmath>
#include <span>
#include <vector>

namespace rtr {
namespace {

struct P2 {
  double x, y;
};

double cross(P2 a, P2 b, P2 c) { return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x); }

// Inside or on the boundary of the counter-clockwise triangle abc.
bool inTriangle(P2 p, P2 a, P2 b, P2 c) { return cross(a, b, p) >= 0 && cross(b, c, p) >= 0 && cross(c, a, p) >= 0; }

bool same(P2 a, P2 b) { return a.x == b.x && a.y == b.y; }

}  // namespace

bool triangulatePolygon(std::span<const glm::vec3> poly, std::vector<std::array<uint32_t, 3>>& out) {
  const uint32_t n = uint32_t(poly.size());
  if (n < 3) return true;
  auto fan = [&](const std::vector<uint32_t>& v) {
    for (size_t k = 1; k + 1 < v.size(); ++k) out.push_back({v[0], v[k], v[k + 1]});
  };
  if (n == 3) return out.push_back({0, 1, 2}), true;

  // Newell normal; project onto the plane of its largest axis, oriented so the polygon turns left.
  glm::dvec3 nn(0.0);
  for (uint32_t i = 0; i < n; ++i) {
    const glm::dvec3 a(poly[i]), b(poly[(i + 1) % n]);
    nn += glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
  }
  const glm::dvec3 an = glm::abs(nn);
  const int axis = an.x > an.y && an.x > an.z ? 0 : an.y > an.z ? 1 : 2;
  const int u = (axis + 1) % 3, w = (axis + 2) % 3;
  const double flip = nn[axis] < 0 ? -1.0 : 1.0;
  // Polygons of up to 8 corners (nearly every face) project on the stack: no allocation for the common case.
  std::array<P2, 8> small;
  std::vector<P2> large(n > small.size() ? n : 0);
  const std::span<P2> p = n <= small.size() ? std::span<P2>(small.data(), n) : std::span<P2>(large);
  for (uint32_t i = 0; i < n; ++i) p[i] = {double(poly[i][u]), flip * double(poly[i][w])};

  // Convex (no right turn): the fan, exactly as before ear clipping existed.
  bool convex = true;
  for (uint32_t i = 0; i < n && convex; ++i) convex = cross(p[(i + n - 1) % n], p[i], p[(i + 1) % n]) >= 0;
  if (convex || nn == glm::dvec3(0.0)) {
    for (uint32_t k = 1; k + 1 < n; ++k) out.push_back({0, k, k + 1});
    return true;
  }
  std::vector<uint32_t> v(n);
  for (uint32_t i = 0; i < n; ++i) v[i] = i;

  // Ear clipping: a corner is an ear when it turns left and no other remaining corner lies in or on its
  // triangle (corners at the same place as the triangle's, as in polygons with bridged holes, don't count).
  // Corners that make no turn are dropped without a triangle.
  size_t i = 0, sinceLastEar = 0;
  while (v.size() > 3) {
    if (sinceLastEar > v.size()) return fan(v), false;  // went all the way round: no ear left
    const size_t m = v.size();
    const uint32_t a = v[(i + m - 1) % m], b = v[i % m], c = v[(i + 1) % m];
    const double turn = cross(p[a], p[b], p[c]);
    bool ear = turn > 0;
    for (size_t k = 0; ear && k < m; ++k) {
      const uint32_t q = v[k];
      if (q == a || q == b || q == c || same(p[q], p[a]) || same(p[q], p[b]) || same(p[q], p[c])) continue;
      ear = !inTriangle(p[q], p[a], p[b], p[c]);
    }
    if (turn == 0 || ear) {
      if (ear) out.push_back({a, b, c});
      v.erase(v.begin() + std::ptrdiff_t(i % m));
      sinceLastEar = 0;
      i = (i % m) == 0 ? 0 : (i % m) - 1;  // the previous corner may have become an ear
    } else {
      ++i;
      ++sinceLastEar;
    }
  }
  if (cross(p[v[0]], p[v[1]], p[v[2]]) != 0) out.push_back({v[0], v[1], v[2]});
  return true;
}

}  // namespace rtr
