#pragma once
// An 8-wide bounding volume hierarchy over triangles, built top-down with a binned surface area
// heuristic and stored flat for traversal: each node holds its eight children's boxes in SoA form so
// one AVX2 box test (or two SSE ones) covers them, and leaves hold triangles in packs of eight laid out
// for an 8-wide watertight test. See docs/tracer.md.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

#include "trace/intersect.hpp"
#include "trace/ray.hpp"

namespace rtr::trace {

struct alignas(64) TriPack {
  float v[3][3][8];  // [vertex][axis][lane]; a short pack repeats its last triangle
  uint32_t prim[8];  // triangle index per lane; the top bit set: the lane casts no shadow (a light)
};

struct alignas(64) Node {
  float box[2][3][8];  // [min, max][axis][child]; an empty slot has min = +inf, max = -inf
  uint32_t child[8];   // inner node index, or leaf: kLeafBit | (packs - 1) << 28 | first pack
};

struct BvhStats {
  uint32_t nodes = 0, packs = 0, triangles = 0, maxDepth = 0;
  double buildSeconds = 0.0;
  double refSeconds = 0.0, treeSeconds = 0.0;  // of it: the references, the tree (the rest: copy-out)
};

// What the traversals did, counted only while Bvh::setCounting(true) (a separate, counting copy of the
// traversal runs then: the timed ones count nothing). Per thread; reset it with Bvh::counters() = {}.
struct BvhCounters {
  // One ray against eight boxes or triangles (lanes = boxes, triangles): node visits, leaf visits, packs
  // and real triangles (not padding) tested. Single rays, a packet's rays walking on alone or traced
  // again, and leaves a packet tests ray by ray.
  uint64_t nodes = 0, leaves = 0, packs = 0, triangles = 0;
  // Eight rays against one box or triangle (lanes = rays): packets walked, their node visits and the rays
  // live at each, the packet's interval against a node's eight boxes (lanes = boxes), child boxes tested and the rays tested at each, leaf visits and the rays live at each,
  // triangles tested against all live rays at once and the rays in those tests, rays left to walk on
  // alone, rays traced again (near-ties).
  uint64_t packets = 0, packetNodes = 0, packetNodeRays = 0, intervalTests = 0, childTests = 0, childTestRays = 0;
  uint64_t packetLeaves = 0, packetLeafRays = 0, triangleTests = 0, packetTriangles = 0, lone = 0, retries = 0;
};

// A fixed-size array in memory the kernel is asked to back with 2 MB pages (transparent huge pages):
// traversal jumps all over tens of MB, and 4 KB pages would miss the TLB on most node visits.
template <class T>
class HugeArray {
 public:
  HugeArray() = default;
  explicit HugeArray(size_t n);
  T* data() const { return p_.get(); }
  size_t size() const { return n_; }
  T& operator[](size_t i) const { return p_[i]; }

 private:
  struct Free {
    void operator()(T* p) const;
  };
  std::unique_ptr<T[], Free> p_;
  size_t n_ = 0;
};

// The instruction set the traversal runs with: the best the CPU has (same results with each). AVX-512VL
// runs the AVX2 code with 32 vector registers instead of 16 (no spills in the traversal loop).
enum class BvhIsa { Sse, Avx2, Avx512 };

// What a closest-hit packet's rays are: a view's rays (neighbours stay together down to the leaves) or
// scattered secondary rays (reflections: they part after a few nodes). It chooses when the packet's last
// live rays walk on as single rays (Bvh::kPacketAloneRays); the results are the same either way.
enum class PacketKind { Coherent, Scattered };

class Bvh {
 public:
  static constexpr uint32_t kLeafBit = 0x80000000u;
  static constexpr uint32_t kNoShadowBit = 0x80000000u;
  static constexpr uint32_t kMaxLeafTriangles = 16;
  static constexpr uint32_t kMaxTriangles = 0x7FFFFFFFu;

  Bvh() = default;
  // castsShadow: one flag per triangle (empty = all cast). threads: 0 = all cores. Throws rtr::Error
  // for more than kMaxTriangles triangles.
  Bvh(std::span<const Triangle> triangles, std::span<const uint8_t> castsShadow = {}, unsigned threads = 0);

  // The build's grain: a subtree of this many triangles or more is a task of its own, and a range is
  // binned and partitioned by many threads in chunks of at least this many references (while a level of
  // the tree has fewer nodes than threads). The tree is the same for any values; for benchmarks only.
  static constexpr uint32_t kSubtreeTask = 4096, kParallelChunk = 16 * 1024;
  static void setBuildGrain(uint32_t subtreeTask, uint32_t parallelChunk);

  // Closest hit in (0, ray.tMax), front to back.
  Hit closest(const Ray& ray, IntersectMethod method = IntersectMethod::Watertight) const;
  // Any shadow-casting triangle in (0, ray.tMax); stops at the first.
  bool occluded(const Ray& ray, IntersectMethod method = IntersectMethod::Watertight) const;
  // The same for two rays at once, each with exactly the result it gets alone: the two walks are
  // interleaved, one node or leaf of each in turn, which keeps the core busier than one walk can
  // (more rays per second on long walks, nothing on rays that end after a few nodes: docs/bench/trace.md,
  // round 5). Rays parallel to different axes go one at a time.
  std::array<Hit, 2> closestPair(const std::array<Ray, 2>& rays, IntersectMethod method = IntersectMethod::Watertight) const;
  std::array<bool, 2> occludedPair(const std::array<Ray, 2>& rays, IntersectMethod method = IntersectMethod::Watertight) const;

  // Packets of up to eight coherent rays (neighbouring pixels, shadow rays to one light), each with
  // exactly its single-ray result: the boxes are tested for all rays at once, the leaves too or ray by ray, and
  // a ray left alone in a subtree walks on as a single ray (bvh_packet.inl). Rays that run parallel to
  // different axes, or another method than Watertight, go one at a time. n > 8 is taken as 8.
  void closest8(const Ray* rays, int n, Hit* hits, IntersectMethod method = IntersectMethod::Watertight,
                PacketKind kind = PacketKind::Coherent) const;
  // Bit i set: ray i is occluded.
  unsigned occluded8(const Ray* rays, int n, IntersectMethod method = IntersectMethod::Watertight) const;

  // A packet tests a leaf with lanes = rays (each triangle against all its live rays at once) when at
  // least this many rays are live there and all share the watertight test's axis order; else ray by ray
  // (lanes = triangles). For tests and benchmarks: setPacketLeafRays(9) = always ray by ray.
  static constexpr int kPacketLeafRays = 5;
  static void setPacketLeafRays(int n);
  // A packet with this many live rays or fewer walks on as single rays, two at a time: two interleaved
  // single walks beat a packet of few live lanes once its rays have parted. Per kind: closest hit
  // coherent (a view's rays stay together: only a last ray walks alone), closest hit scattered, any hit
  // (shadow rays to one light); from the 16-core host's runs of rounds 10-11 (docs/bench/trace.md,
  // round 12). For tests and benchmarks: setPacketAloneRays.
  static constexpr int kPacketAloneRays[3] = {1, 4, 4};
  static void setPacketAloneRays(int coherent, int scattered, int shadow);
  // Counting (tests and benchmarks): while on, every query of this process runs the counting traversal
  // (the AVX2 code, slower; no counting on a CPU without AVX2) and adds to its thread's counters.
  static void setCounting(bool on);
  static BvhCounters& counters();

  const BvhStats& stats() const { return stats_; }
  // The tree's expected node and pack tests of a ray through the root box (bvh.cpp): computed when asked,
  // not by the build (a walk over every node, 2-4 % of a 16-thread build's time).
  double sahCost() const;
  bool empty() const { return root_ == kEmpty; }

  // For tests and benchmarks: pick the ISA, or the best below it that the CPU supports; returns the one
  // in use.
  static BvhIsa setIsa(BvhIsa isa);
  static BvhIsa isa();
  static const char* isaName(BvhIsa isa);

  // What a traversal needs; the per-ISA traversals live in bvh_traverse.inl.
  struct View {
    const Node* nodes;
    const TriPack* packs;
    uint32_t root;
  };
  View view() const { return {nodes_.data(), packs_.data(), root_}; }  // also for tests of the tree

 private:
  static constexpr uint32_t kEmpty = 0xFFFFFFFFu;
  HugeArray<Node> nodes_;
  HugeArray<TriPack> packs_;
  uint32_t root_ = kEmpty;
  BvhStats stats_;
  friend struct BvhBuilder;
};

}  // namespace rtr::trace
