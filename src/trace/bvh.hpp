#pragma once
// A 4-wide bounding volume hierarchy over triangles, built top-down with a binned surface area
// heuristic and stored flat for traversal: each node holds its four children's boxes in SoA form so
// one SSE box test covers them, and leaves hold triangles in packs of four laid out for a 4-wide
// watertight test. See docs/tracer.md.
#include <cstdint>
#include <span>
#include <vector>

#include "trace/intersect.hpp"
#include "trace/ray.hpp"

namespace rtr::trace {

struct alignas(16) TriPack {
  float v[3][3][4];        // [vertex][axis][lane]; a short pack repeats its last triangle
  uint32_t prim[4];        // triangle index per lane
  uint32_t occluderMask;   // lanes that cast shadows (light geometry does not)
  uint32_t pad[3];
};

struct alignas(64) Node4 {
  float box[2][3][4];  // [min, max][axis][child]; an empty slot has min = +inf, max = -inf
  uint32_t child[4];   // inner node index, or leaf: kLeafBit | (packs - 1) << 28 | first pack
};

struct BvhStats {
  uint32_t nodes = 0, packs = 0, triangles = 0, maxDepth = 0;
  double buildSeconds = 0.0;
  double sahCost = 0.0;
};

class Bvh {
 public:
  static constexpr uint32_t kLeafBit = 0x80000000u;
  static constexpr uint32_t kMaxLeafTriangles = 8;

  Bvh() = default;
  // castsShadow: one flag per triangle (empty = all cast). threads: 0 = all cores.
  Bvh(std::span<const Triangle> triangles, std::span<const uint8_t> castsShadow = {}, unsigned threads = 0);

  // Closest hit in (0, ray.tMax), front to back.
  Hit closest(const Ray& ray, IntersectMethod method = IntersectMethod::Watertight) const;
  // Any shadow-casting triangle in (0, ray.tMax); stops at the first.
  bool occluded(const Ray& ray, IntersectMethod method = IntersectMethod::Watertight) const;

  const BvhStats& stats() const { return stats_; }
  bool empty() const { return root_ == kEmpty; }

 private:
  static constexpr uint32_t kEmpty = 0xFFFFFFFFu;
  template <bool AnyHit>
  bool traverse(const Ray& ray, IntersectMethod method, Hit& hit) const;

  std::vector<Node4> nodes_;
  std::vector<TriPack> packs_;
  uint32_t root_ = kEmpty;
  BvhStats stats_;
  friend struct BvhBuilder;
};

}  // namespace rtr::trace
