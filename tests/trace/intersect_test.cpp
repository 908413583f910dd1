// Ray-triangle routines: the hard cases (closed mesh from inside, shared diagonal, grazing,
// parallel and degenerate), for each routine; miss rates of the non-watertight ones are reported.
#include "trace/intersect.hpp"

#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "trace/bvh.hpp"
#include "trace/procedural.hpp"

namespace rtr::trace {
namespace {

constexpr IntersectMethod kMethods[] = {IntersectMethod::HalfPlane, IntersectMethod::MollerTrumbore, IntersectMethod::Watertight};
const char* name(IntersectMethod m) {
  return m == IntersectMethod::HalfPlane ? "halfplane" : m == IntersectMethod::Watertight ? "watertight" : "moller";
}

std::vector<Triangle> trianglesOf(const Mesh& m) {
  std::vector<Triangle> t;
  for (size_t i = 0; i < m.indices.size(); i += 3)
    t.push_back({m.positions[m.indices[i]], m.positions[m.indices[i + 1]], m.positions[m.indices[i + 2]]});
  return t;
}

// Number of triangles the ray hits, testing every one.
int hitCount(IntersectMethod m, const Ray& r, const std::vector<Triangle>& tris) {
  int n = 0;
  for (const Triangle& t : tris) {
    float b1 = NAN, b2 = NAN;
    const float tt = intersect(m, r, t, b1, b2);
    if (tt > 0.0f) {
      EXPECT_TRUE(std::isfinite(tt) && std::isfinite(b1) && std::isfinite(b2));
      ++n;
    }
  }
  return n;
}

TEST(Intersect, RoutinesAgreeOnAPlainHit) {
  const Triangle tri{{-1, -1, -2}, {1, -1, -2}, {0, 1, -2}};
  const Ray r{{0.1f, 0.2f, 0.0f}, {0.0f, 0.0f, -1.0f}};
  for (IntersectMethod m : kMethods) {
    float b1 = -1, b2 = -1;
    EXPECT_FLOAT_EQ(intersect(m, r, tri, b1, b2), 2.0f) << name(m);
    const glm::vec3 p = (1 - b1 - b2) * tri.v0 + b1 * tri.v1 + b2 * tri.v2;
    EXPECT_NEAR(p.x, 0.1f, 1e-6f) << name(m);
    EXPECT_NEAR(p.y, 0.2f, 1e-6f) << name(m);
    // The brief's barycentric() of the hit point gives the same weights.
    const glm::vec3 bc = barycentric(tri, r.origin + 2.0f * r.direction);
    EXPECT_NEAR(bc.y, b1, 1e-6f);
    EXPECT_NEAR(bc.z, b2, 1e-6f);
    // Behind the origin, and beyond tMax: no hit (negative t).
    EXPECT_LT(intersect(m, {{0.1f, 0.2f, -3.0f}, {0, 0, -1}}, tri, b1, b2), 0.0f) << name(m);
    EXPECT_LT(intersect(m, {{0.1f, 0.2f, 0.0f}, {0, 0, -1}, 1.5f}, tri, b1, b2), 0.0f) << name(m);
    // Outside the triangle.
    EXPECT_LT(intersect(m, {{0.9f, 0.9f, 0.0f}, {0, 0, -1}}, tri, b1, b2), 0.0f) << name(m);
  }
}

// A closed sphere hit from inside: every ray must hit. Watertight: exactly one triangle per ray, for
// random rays, rays aimed exactly at vertices and rays aimed along shared edges.
// Far from the origin, the BVH's slab test works with large coordinates and small differences.
void expectClosedSphereWatertight(std::mt19937& rng, float radius, glm::vec3 centre) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const Mesh sphere = uvSphere(centre, radius, 16, 16);
  const std::vector<Triangle> tris = trianglesOf(sphere);
  const Bvh bvh(tris);
  auto insidePoint = [&] {
    for (;;) {
      const glm::vec3 p{u(rng), u(rng), u(rng)};
      if (glm::length(p) < 0.8f) return centre + p * radius * 0.8f;  // well inside every face
    }
  };
  std::vector<Ray> rays;
  for (int i = 0; i < 100000; ++i) rays.push_back({insidePoint(), {u(rng), u(rng), u(rng)}});
  for (const glm::vec3& v : sphere.positions) rays.push_back({insidePoint(), v - insidePoint()});
  for (const glm::vec3& v : sphere.positions) rays.push_back({centre, v - centre});
  for (size_t i = 0; i < sphere.indices.size(); i += 3)  // points on every edge, from several origins
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 a = sphere.positions[sphere.indices[i + k]], b = sphere.positions[sphere.indices[i + (k + 1) % 3]];
      for (float s : {0.5f, 0.25f, 0.125f}) {
        const glm::vec3 o = insidePoint();
        rays.push_back({o, (a + s * (b - a)) - o});
      }
    }
  for (IntersectMethod m : kMethods) {
    // Every ray through the BVH, with each traversal ISA (the same answers); every triangle (to count
    // double hits) for the aimed rays and 10k random.
    size_t misses = 0, doubles = 0, tested = 0, bvhMisses = 0, sseMisses = 0, avx2Misses = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      bvhMisses += !bvh.closest(rays[i], m).hit();
      Bvh::setIsa(BvhIsa::Sse);
      sseMisses += !bvh.closest(rays[i], m).hit();
      Bvh::setIsa(BvhIsa::Avx2);
      avx2Misses += !bvh.closest(rays[i], m).hit();
      Bvh::setIsa(BvhIsa::Avx512);
      if (i >= 10000 && i < 100000) continue;
      const int n = hitCount(m, rays[i], tris);
      ++tested;
      misses += n == 0;
      doubles += n > 1;
    }
    std::printf("[ sphere r=%.3f ] %-10s BVH: %zu of %zu rays miss (%.4f%%); all triangles: %zu of %zu miss, %zu hit twice\n",
                radius, name(m), bvhMisses, rays.size(), 100.0 * double(bvhMisses) / double(rays.size()), misses, tested,
                doubles);
    if (m == IntersectMethod::Watertight) {
      EXPECT_EQ(misses, 0u);
      EXPECT_EQ(doubles, 0u);
      EXPECT_EQ(bvhMisses, 0u);
      EXPECT_EQ(sseMisses, 0u);
      EXPECT_EQ(avx2Misses, 0u);
    }
  }
}

TEST(Intersect, ClosedSphereFromInsideIsWatertight) {
  std::mt19937 rng(1234);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const float radius = 0.5f + 10.0f * (u(rng) + 1.0f);
  expectClosedSphereWatertight(rng, radius, {u(rng) * 3.0f, u(rng) * 3.0f, u(rng) * 3.0f});
}

TEST(Intersect, ClosedSphereFarFromTheOriginIsWatertight) {
  std::mt19937 rng(99);
  expectClosedSphereWatertight(rng, 0.75f, {3000.0f, -2000.0f, 1000.0f});
}

// A unit quad split along y = x, hit exactly on (near) the diagonal from above at several angles.
TEST(Intersect, SharedDiagonalIsHitByExactlyOneTriangle) {
  const std::vector<Triangle> tris{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, {{0, 0, 0}, {1, 1, 0}, {0, 1, 0}}};
  const Bvh bvh(tris);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (IntersectMethod m : kMethods) {
    size_t rays = 0, zero = 0, two = 0, closestMiss = 0;
    for (float angle : {0.0f, 10.0f, 30.0f, 45.0f, 60.0f, 80.0f, 89.0f}) {
      for (int i = 0; i < 2000; ++i) {
        const float s = u(rng);
        const float a = glm::radians(angle), phi = 6.2831853f * u(rng);
        const glm::vec3 d{std::sin(a) * std::cos(phi), std::sin(a) * std::sin(phi), -std::cos(a)};
        for (const glm::vec3& target : {glm::vec3{s, s, 0.0f}, glm::vec3{0.5f, 0.5f, 0.0f}}) {
          const Ray r{target - 3.0f * d, d};
          const int n = hitCount(m, r, tris);
          ++rays;
          zero += n == 0;
          two += n == 2;
          closestMiss += !bvh.closest(r, m).hit();
        }
      }
    }
    std::printf("[ diagonal, %zu rays ] %-10s no hit %zu, both hit %zu, closest-hit misses %zu\n", rays, name(m), zero, two,
                closestMiss);
    if (m == IntersectMethod::Watertight) {
      // The quad's own corners lie on the open mesh's border: at most one owner there.
      for (const glm::vec3& corner : {glm::vec3{0, 0, 0}, glm::vec3{1, 1, 0}, glm::vec3{1, 0, 0}})
        EXPECT_LE(hitCount(m, {corner + glm::vec3(0.1f, 0.2f, 1.0f), {-0.1f, -0.2f, -1.0f}}, tris), 1);
      EXPECT_EQ(zero, 0u);
      EXPECT_EQ(two, 0u);
      EXPECT_EQ(closestMiss, 0u);
    }
  }
}

TEST(Intersect, GrazingParallelAndDegenerateGiveNoHitAndNoNaN) {
  const Triangle tri{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<Triangle> degenerate{{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}},   // collinear
                                         {{1, 2, 3}, {1, 2, 3}, {1, 2, 3}},   // a point
                                         {{0, 0, 0}, {1, 0, 0}, {1, 0, 0}}};  // two equal vertices
  for (IntersectMethod m : kMethods) {
    float b1 = 0, b2 = 0;
    // In the triangle's plane, straight through it.
    EXPECT_LT(intersect(m, {{-1.0f, 0.25f, 0.0f}, {1, 0, 0}}, tri, b1, b2), 0.0f) << name(m);
    EXPECT_LT(intersect(m, {{0.25f, 0.25f, 0.0f}, {1, 1, 0}}, tri, b1, b2), 0.0f) << name(m);
    // Parallel, just above.
    EXPECT_LT(intersect(m, {{-1.0f, 0.25f, 1e-3f}, {1, 0, 0}}, tri, b1, b2), 0.0f) << name(m);
    // Zero direction.
    EXPECT_LT(intersect(m, {{0.25f, 0.25f, 1.0f}, {0, 0, 0}}, tri, b1, b2), 0.0f) << name(m);
    // Degenerate triangles, hit right through their points.
    for (const Triangle& d : degenerate) {
      for (const glm::vec3& dir : {glm::vec3{0, 0, -1}, glm::vec3{1, -1, 0.5f}, glm::vec3{-1, 0, 0}}) {
        const Ray r{d.v1 - 2.0f * dir, dir};
        b1 = b2 = 0;
        EXPECT_LT(intersect(m, r, d, b1, b2), 0.0f) << name(m);
      }
    }
    // Grazing: nearly in the plane. Hit or not, the answer is finite.
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 0; i < 1000; ++i) {
      const glm::vec3 d{1.0f, u(rng) - 0.5f, -std::ldexp(u(rng), -int(u(rng) * 40))};
      const Ray r{{-1.0f, 0.25f, -d.z * 1.2f}, d};
      b1 = b2 = 0;
      const float t = intersect(m, r, tri, b1, b2);
      if (t > 0.0f) {
        EXPECT_TRUE(std::isfinite(t) && std::isfinite(b1) && std::isfinite(b2)) << name(m);
      } else {
        EXPECT_FALSE(std::isnan(t)) << name(m);
      }
    }
  }
}

}  // namespace
}  // namespace rtr::trace
