// The BVH against brute force: same closest hits, any-hit agrees, shadow flags respected.
#include "trace/bvh.hpp"

#include <random>

#include <gtest/gtest.h>

namespace rtr::trace {
namespace {

Hit bruteForce(const std::vector<Triangle>& tris, Ray r, IntersectMethod m) {
  Hit best;
  for (uint32_t i = 0; i < tris.size(); ++i) {
    float b1, b2;
    const float t = intersect(m, r, tris[i], b1, b2);
    if (t > 0.0f) { best = {t, b1, b2, i}; r.tMax = t; }
  }
  return best;
}

TEST(Bvh, MatchesBruteForceOnATriangleSoup) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Triangle> tris;
  for (int i = 0; i < 3000; ++i) {
    const glm::vec3 c{u(rng) * 10, u(rng) * 10, u(rng) * 10};
    tris.push_back({c, c + glm::vec3{u(rng), u(rng), u(rng)}, c + glm::vec3{u(rng), u(rng), u(rng)}});
  }
  std::vector<uint8_t> casts(tris.size(), 1);
  const Bvh bvh(tris, casts, 2);
  EXPECT_GT(bvh.stats().nodes, 10u);
  EXPECT_EQ(bvh.stats().triangles, tris.size());
  // Both traversal ISAs (where the CPU has AVX2; else SSE twice), every routine.
  for (BvhIsa isa : {BvhIsa::Avx2, BvhIsa::Sse})
  for (IntersectMethod m : {IntersectMethod::Watertight, IntersectMethod::HalfPlane, IntersectMethod::MollerTrumbore}) {
    Bvh::setIsa(isa);
    int hits = 0;
    for (int i = 0; i < 3000; ++i) {
      Ray r{{u(rng) * 12, u(rng) * 12, u(rng) * 12}, {u(rng), u(rng), u(rng)}};
      if (i % 3 == 0) r.direction.y = 0.0f;  // axis-parallel components exercise the slab test's zero case
      if (i % 7 == 0) r.tMax = 5.0f;
      const Hit a = bvh.closest(r, m), b = bruteForce(tris, r, m);
      ASSERT_EQ(a.hit(), b.hit()) << i;
      ASSERT_EQ(bvh.occluded(r, m), b.hit()) << i;
      if (a.hit()) {
        ++hits;
        EXPECT_EQ(a.t, b.t) << i;
        EXPECT_EQ(a.prim, b.prim) << i;
        EXPECT_EQ(a.b1, b.b1) << i;
      }
    }
    EXPECT_GT(hits, 300);
  }
  Bvh::setIsa(BvhIsa::Avx2);
}

TEST(Bvh, ShadowRaysIgnoreNonCasters) {
  const std::vector<Triangle> tris{{{-1, -1, -1}, {1, -1, -1}, {0, 1, -1}}, {{-1, -1, -2}, {1, -1, -2}, {0, 1, -2}}};
  const Ray r{{0, 0, 0}, {0, 0, -1}};
  EXPECT_TRUE(Bvh(tris, std::vector<uint8_t>{1, 1}).occluded(r));
  EXPECT_TRUE(Bvh(tris, std::vector<uint8_t>{0, 1}).occluded(r));
  EXPECT_FALSE(Bvh(tris, std::vector<uint8_t>{0, 0}).occluded(r));
  // Closest hit still sees non-casters (lights are visible).
  EXPECT_EQ(Bvh(tris, std::vector<uint8_t>{0, 0}).closest(r).prim, 0u);
}

TEST(Bvh, EmptyAndDegenerateInputs) {
  const Bvh empty(std::vector<Triangle>{});
  EXPECT_FALSE(empty.closest({{0, 0, 0}, {0, 0, -1}}).hit());
  // Many triangles with the same centroid: the build must still terminate and find them.
  std::vector<Triangle> same(100, Triangle{{-1, -1, -1}, {1, -1, -1}, {0, 1, -1}});
  const Bvh bvh(same);
  EXPECT_TRUE(bvh.closest({{0, 0, 0}, {0, 0, -1}}).hit());
  // Non-finite coordinates are left out rather than poisoning the boxes.
  std::vector<Triangle> bad{{{NAN, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{-1, -1, -1}, {1, -1, -1}, {0, 1, -1}}};
  EXPECT_EQ(Bvh(bad).closest({{0, 0, 0}, {0, 0, -1}}).prim, 1u);
}

}  // namespace
}  // namespace rtr::trace
