#include "trace/bvh.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <vector>

#include <smmintrin.h>
#include <sys/mman.h>

#include <glm/common.hpp>

#include "core/error.hpp"
#include "core/parallel.hpp"

namespace rtr::trace {
namespace {

constexpr int kBins = 32;
constexpr uint32_t kWidth = 8;     // children per node, triangles per pack
constexpr float kNodeCost = 0.5f;  // one 8-wide box test against one 8-wide pack test
constexpr float kInf = std::numeric_limits<float>::infinity();

// x, y, z in the first three lanes of an SSE register (the fourth 0): one instruction grows a box.
// The operand order of min/max is glm's (min(a, b) = b < a ? b : a), so signed zeros land as before.
struct Box {
  __m128 lo = _mm_set1_ps(kInf), hi = _mm_set1_ps(-kInf);
  void grow(__m128 p) {
    lo = _mm_min_ps(p, lo);
    hi = _mm_max_ps(p, hi);
  }
  void grow(const Box& b) {
    lo = _mm_min_ps(b.lo, lo);
    hi = _mm_max_ps(b.hi, hi);
  }
  float halfArea() const {
    alignas(16) float e[4];
    _mm_store_ps(e, _mm_max_ps(_mm_setzero_ps(), _mm_sub_ps(hi, lo)));
    return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
  }
};

__m128 load3(const glm::vec3& v) { return _mm_set_ps(0.0f, v.z, v.y, v.x); }
float lane(__m128 v, int a) {
  alignas(16) float f[4];
  _mm_store_ps(f, v);
  return f[a];
}

// A triangle's box, its index kept in the fourth lane of `lo` (32 bytes, aligned: one load each).
struct PrimRef {
  __m128 lo, hi;
  uint32_t id() const { return uint32_t(_mm_extract_epi32(_mm_castps_si128(lo), 3)); }
  __m128 boxLo() const { return _mm_blend_ps(lo, _mm_setzero_ps(), 8); }  // the index out of the way
  Box box() const { return {boxLo(), hi}; }
  __m128 centroid2() const { return _mm_add_ps(boxLo(), hi); }  // twice the centroid: saves a multiply
};

// The bin of each axis: int((c - lo) · scale) clamped to [0, kBins), as one SSE computation.
__m128i binOf(__m128 c, __m128 lo, __m128 scale) {
  const __m128i k = _mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(c, lo), scale));
  return _mm_min_epi32(_mm_max_epi32(k, _mm_setzero_si128()), _mm_set1_epi32(kBins - 1));
}

struct Range {
  uint32_t begin = 0, end = 0;
  Box bounds, cbounds;  // of the triangles, and of their (doubled) centroids
  uint32_t depth = 0;
  uint32_t size() const { return end - begin; }
};

uint32_t packsFor(uint32_t n) { return (n + kWidth - 1) / kWidth; }

// The tree's SAH cost as the builder counts it: per node kNodeCost, per leaf its packs, each weighted by
// its box's area relative to the root's (the expected work of a ray that meets the root box).
double treeSahCost(const Node* nodes, uint32_t root) {
  const auto area = [](const Node& n, int k) {
    const double e[3] = {double(n.box[1][0][k]) - n.box[0][0][k], double(n.box[1][1][k]) - n.box[0][1][k],
                         double(n.box[1][2][k]) - n.box[0][2][k]};
    return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
  };
  if (root & Bvh::kLeafBit) return double(((root >> 28) & 7u) + 1);
  double total = 0.0, rootArea = 0.0;
  Box rootBox;
  std::vector<uint32_t> stack{root};
  while (!stack.empty()) {
    const Node& n = nodes[stack.back()];
    stack.pop_back();
    for (int k = 0; k < int(kWidth); ++k) {
      if (!(n.box[0][0][k] <= n.box[1][0][k])) continue;  // empty slot
      if (&n == &nodes[root])
        rootBox.grow(Box{_mm_set_ps(0, n.box[0][2][k], n.box[0][1][k], n.box[0][0][k]),
                         _mm_set_ps(0, n.box[1][2][k], n.box[1][1][k], n.box[1][0][k])});
      const uint32_t c = n.child[k];
      if (c & Bvh::kLeafBit) total += area(n, k) * double(((c >> 28) & 7u) + 1);
      else {
        total += area(n, k) * kNodeCost;
        stack.push_back(c);
      }
    }
  }
  rootArea = rootBox.halfArea();
  return rootArea > 0.0 ? kNodeCost + total / rootArea : 0.0;
}

std::atomic<uint32_t> buildGrain[2] = {Bvh::kSubtreeTask, Bvh::kParallelChunk};

}  // namespace

void Bvh::setBuildGrain(uint32_t subtreeTask, uint32_t parallelChunk) {
  buildGrain[0] = std::max(1u, subtreeTask);
  buildGrain[1] = std::max(1u, parallelChunk);
}

// Top-down build straight into 8-wide nodes: a node's range is split by binned SAH, and the child with
// the largest area is split again until there are eight, as in Wald 2007 / Embree's BVH8 builder.
struct BvhBuilder {
  std::span<const Triangle> tris;
  std::span<const uint8_t> casts;
  std::unique_ptr<PrimRef[]> refs;
  std::unique_ptr<Node[]> nodes;
  // Per leaf its refs [begin, end): the packs are written once, straight into their place, by the copy-out.
  std::unique_ptr<std::array<uint32_t, 2>[]> leaves;
  std::unique_ptr<std::array<uint32_t, 2>[]> subtree;  // per node: nodes and packs of its subtree, itself included
  std::atomic<uint32_t> nodeCount{0}, leafCount{0}, packCount{0}, maxDepth{0};
  ThreadPool* pool = nullptr;  // none for one thread
  uint32_t threads = 1;
  // Triangles from which a subtree is a task of its own; refs a chunk at least, when binned by many threads
  // (Bvh::kSubtreeTask, kParallelChunk; set for benchmarks by Bvh::setBuildGrain: the tree is the same).
  const uint32_t subtreeTask = buildGrain[0].load(), parallelChunk = buildGrain[1].load();
  static constexpr uint32_t kSmallRange = 24;  // ranges up to this size: findSplitSmall

  struct Split {
    int axis = -1, bin = 0;
    float cost = kInf;
    Range left, right;
  };

  // Boxes and counts only: the children's centroid bounds come from the partition, which looks at every
  // centroid anyway (half the bins to clear and grow).
  struct Bins {
    Box b[3][kBins];
    uint32_t n[3][kBins] = {};
    // Min, max and sums: exact and order-free, so the bins (and the split) do not depend on how the
    // range was cut up between threads.
    void merge(const Bins& o) {
      for (int a = 0; a < 3; ++a)
        for (int k = 0; k < kBins; ++k) {
          b[a][k].grow(o.b[a][k]);
          n[a][k] += o.n[a][k];
        }
    }
  };

  // Adds refs [begin, end) to `out`.
  void binRefs(uint32_t begin, uint32_t end, __m128 lo, __m128 scale, Bins& out) const {
    const PrimRef* ref = refs.get();
    for (uint32_t i = begin; i < end; ++i) {
      const __m128 blo = ref[i].boxLo(), bhi = ref[i].hi;
      const __m128i k = binOf(_mm_add_ps(blo, bhi), lo, scale);
      // Written out per axis, the bin numbers straight from the register (a loop over the axes through
      // memory: a slower tree phase).
      const auto add = [&](int a, int bin) {
        Box& b = out.b[a][bin];
        b.lo = _mm_min_ps(blo, b.lo);
        b.hi = _mm_max_ps(bhi, b.hi);
        ++out.n[a][bin];
      };
      add(0, _mm_cvtsi128_si32(k));
      add(1, _mm_extract_epi32(k, 1));
      add(2, _mm_extract_epi32(k, 2));
    }
  }

  // How many threads bin and partition a range of a node at `level` (the root: 0): while a level of the
  // tree has fewer nodes than there are threads, there are not yet subtrees enough to run side by side,
  // so each node's splits are shared out (chunks of at least parallelChunk references).
  uint32_t chunksFor(const Range& r, uint32_t level) const {
    if (level < 10 && (1u << (3 * level)) >= threads) return 1;
    return std::min(threads, r.size() / parallelChunk);
  }

  // Binned SAH over all three axes in one pass. Cost counts packs of eight, since a leaf's price is the
  // number of 8-wide triangle tests it takes.
  Split findSplit(const Range& r, uint32_t level) const {
    alignas(16) float ext[4], sc[4] = {};
    _mm_store_ps(ext, _mm_sub_ps(r.cbounds.hi, r.cbounds.lo));
    for (int a = 0; a < 3; ++a) sc[a] = ext[a] > 0.0f ? float(kBins) * 0.99999f / ext[a] : 0.0f;
    const __m128 scale = _mm_load_ps(sc);
    if (r.size() <= kSmallRange) return findSplitSmall(r, scale, ext);
    Bins all;
    const uint32_t chunks = chunksFor(r, level);
    if (chunks > 1) {
      std::vector<Bins> part(chunks);
      const auto cut = [&](uint32_t c) { return r.begin + uint32_t(uint64_t(r.size()) * c / chunks); };
      chunked(chunks, [&](uint32_t c) { binRefs(cut(c), cut(c + 1), r.cbounds.lo, scale, part[c]); });
      for (const Bins& p : part) all.merge(p);
    } else {
      binRefs(r.begin, r.end, r.cbounds.lo, scale, all);
    }
    // The sweeps of the three axes side by side, lane a = axis a: the same arithmetic as one axis at a
    // time (halfArea's order of operations, glm's operand order), so the same costs to the bit.
    __m128 lo[3][kBins], hi[3][kBins];  // [x, y, z][bin], lanes: axes
    __m128i count[kBins];
    for (int k = 0; k < kBins; ++k) {
      __m128 l0 = all.b[0][k].lo, l1 = all.b[1][k].lo, l2 = all.b[2][k].lo, l3 = _mm_setzero_ps();
      __m128 h0 = all.b[0][k].hi, h1 = all.b[1][k].hi, h2 = all.b[2][k].hi, h3 = _mm_setzero_ps();
      _MM_TRANSPOSE4_PS(l0, l1, l2, l3);
      _MM_TRANSPOSE4_PS(h0, h1, h2, h3);
      lo[0][k] = l0;
      lo[1][k] = l1;
      lo[2][k] = l2;
      hi[0][k] = h0;
      hi[1][k] = h1;
      hi[2][k] = h2;
      count[k] = _mm_set_epi32(0, int(all.n[2][k]), int(all.n[1][k]), int(all.n[0][k]));
    }
    struct Acc {
      __m128 lo[3], hi[3];
      __m128i n = _mm_setzero_si128();
      Acc() {
        for (int i = 0; i < 3; ++i) {
          lo[i] = _mm_set1_ps(kInf);
          hi[i] = _mm_set1_ps(-kInf);
        }
      }
      // Grows by bin k; returns halfArea() · packsFor(n) per axis.
      __m128 add(const __m128 (&l)[3][kBins], const __m128 (&h)[3][kBins], const __m128i* c, int k) {
        __m128 e[3];
        for (int i = 0; i < 3; ++i) {
          lo[i] = _mm_min_ps(l[i][k], lo[i]);
          hi[i] = _mm_max_ps(h[i][k], hi[i]);
          e[i] = _mm_max_ps(_mm_setzero_ps(), _mm_sub_ps(hi[i], lo[i]));
        }
        n = _mm_add_epi32(n, c[k]);
        const __m128 area = _mm_add_ps(_mm_add_ps(_mm_mul_ps(e[0], e[1]), _mm_mul_ps(e[1], e[2])), _mm_mul_ps(e[2], e[0]));
        return _mm_mul_ps(area, _mm_cvtepi32_ps(_mm_srli_epi32(_mm_add_epi32(n, _mm_set1_epi32(int(kWidth) - 1)), 3)));
      }
    };
    __m128 rightCost[kBins];
    Acc acc;
    for (int k = kBins - 1; k > 0; --k) rightCost[k] = acc.add(lo, hi, count, k);
    acc = Acc{};
    const __m128 inf = _mm_set1_ps(kInf);
    const __m128i whole = _mm_set1_epi32(int(r.size()));
    // Axes without extent take no split.
    const __m128 flat = _mm_cmple_ps(_mm_load_ps(ext), _mm_setzero_ps());
    __m128 bestCost = inf;
    __m128i bestBin = _mm_setzero_si128();
    for (int k = 0; k < kBins - 1; ++k) {
      __m128 cost = _mm_add_ps(acc.add(lo, hi, count, k), rightCost[k + 1]);
      const __m128i none = _mm_or_si128(_mm_cmpeq_epi32(acc.n, _mm_setzero_si128()), _mm_cmpeq_epi32(acc.n, whole));
      cost = _mm_blendv_ps(cost, inf, _mm_or_ps(flat, _mm_castsi128_ps(none)));
      const __m128 better = _mm_cmplt_ps(cost, bestCost);  // strictly: the first bin of equal cost wins
      bestCost = _mm_blendv_ps(bestCost, cost, better);
      bestBin = _mm_blendv_epi8(bestBin, _mm_set1_epi32(k), _mm_castps_si128(better));
    }
    alignas(16) float bc[4];
    alignas(16) int bb[4];
    _mm_store_ps(bc, bestCost);
    _mm_store_si128(reinterpret_cast<__m128i*>(bb), bestBin);
    Split best;
    for (int a = 0; a < 3; ++a)  // the first axis of equal cost wins, as in a sweep of one axis after another
      if (bc[a] < best.cost) {
        best.cost = bc[a];
        best.axis = a;
        best.bin = bb[a];
      }
    if (best.axis < 0) return best;
    // Child ranges' bounds straight from the bins (their centroid bounds: partition()).
    Range L, R;
    uint32_t nl = 0;
    for (int k = 0; k < kBins; ++k) {
      (k <= best.bin ? L : R).bounds.grow(all.b[best.axis][k]);
      if (k <= best.bin) nl += all.n[best.axis][k];
    }
    L.begin = r.begin;
    L.end = r.begin + nl;
    R.begin = L.end;
    R.end = r.end;
    L.depth = R.depth = r.depth + 1;
    best.left = L;
    best.right = R;
    return best;
  }

  // The same split for a range of at most kSmallRange references (most splits: the bottom of the tree),
  // without clearing and sweeping all 96 bins: only the bins in use are set and swept, one axis after
  // another. An empty bin adds nothing to either side, so its cost is that of the bin before it and never
  // wins (the first of equal costs does); the sums run in the full sweep's order.
  Split findSplitSmall(const Range& r, __m128 scale, const float* ext) const {
    const uint32_t n = r.size();
    alignas(16) int bin[kSmallRange][4];
    uint32_t used[3] = {};
    for (uint32_t i = 0; i < n; ++i) {
      _mm_store_si128(reinterpret_cast<__m128i*>(bin[i]), binOf(refs[r.begin + i].centroid2(), r.cbounds.lo, scale));
      for (int a = 0; a < 3; ++a) used[a] |= 1u << bin[i][a];
    }
    Box box[3][kBins];  // uninitialised but for the bins in use
    uint32_t count[3][kBins];
    for (int a = 0; a < 3; ++a)
      for (uint32_t u = used[a]; u; u &= u - 1) {
        box[a][__builtin_ctz(u)] = Box{};
        count[a][__builtin_ctz(u)] = 0;
      }
    for (uint32_t i = 0; i < n; ++i)
      for (int a = 0; a < 3; ++a) {
        box[a][bin[i][a]].grow(refs[r.begin + i].box());
        ++count[a][bin[i][a]];
      }
    Split best;
    for (int a = 0; a < 3; ++a) {
      if (!(ext[a] > 0.0f)) continue;
      int list[kBins], m = 0;
      for (uint32_t u = used[a]; u; u &= u - 1) list[m++] = __builtin_ctz(u);
      float rightCost[kBins];  // of bins list[i], list[i + 1], ...
      Box acc;
      uint32_t nr = 0;
      for (int i = m - 1; i > 0; --i) {
        acc.grow(box[a][list[i]]);
        nr += count[a][list[i]];
        rightCost[i] = acc.halfArea() * float(packsFor(nr));
      }
      acc = Box{};
      uint32_t nl = 0;
      for (int i = 0; i + 1 < m; ++i) {
        acc.grow(box[a][list[i]]);
        nl += count[a][list[i]];
        const float cost = acc.halfArea() * float(packsFor(nl)) + rightCost[i + 1];
        if (cost < best.cost) {
          best.cost = cost;
          best.axis = a;
          best.bin = list[i];
        }
      }
    }
    if (best.axis < 0) return best;
    uint32_t nl = 0;
    for (uint32_t u = used[best.axis]; u; u &= u - 1) {
      const int k = __builtin_ctz(u);
      (k <= best.bin ? best.left : best.right).bounds.grow(box[best.axis][k]);
      if (k <= best.bin) nl += count[best.axis][k];
    }
    best.left.begin = r.begin;
    best.left.end = best.right.begin = r.begin + nl;
    best.right.end = r.end;
    best.left.depth = best.right.depth = r.depth + 1;
    return best;
  }

  // fn(c) for c in [0, chunks), on the pool's threads when there is one.
  template <class Fn>
  void chunked(uint32_t chunks, const Fn& fn) const {
    if (pool) parallelFor(*pool, chunks, fn);
    else
      for (uint32_t c = 0; c < chunks; ++c) fn(c);
  }

  // Moves the refs of bins ≤ s.bin in front. The k-th misplaced ref from the front trades places with the
  // k-th misplaced one from the back (Hoare's scheme, as std::partition does it), whether one thread or
  // many do it: the tree does not depend on the thread count.
  // And sets the two sides' centroid bounds (cb[0]: left, cb[1]: right, of every ref looked at).
  void partition(Split& s, const Range& r, uint32_t level) {
    const int a = s.axis;
    // findSplit's bin of axis a (lane a; the other lanes are not looked at).
    const __m128 scale = _mm_set1_ps(float(kBins) * 0.99999f / (lane(r.cbounds.hi, a) - lane(r.cbounds.lo, a)));
    const __m128i bin = _mm_set1_epi32(s.bin);
    const auto isLeft = [&, lo = r.cbounds.lo](__m128 c) {
      return !((_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(binOf(c, lo, scale), bin))) >> a) & 1);
    };
    const auto left = [&](const PrimRef& p, Box* cb) {
      const __m128 c = p.centroid2();
      const bool l = isLeft(c);
      cb[!l].grow(c);
      return l;
    };
    const uint32_t chunks = chunksFor(r, level);
    if (chunks <= 1) {
      Box cl, cr;  // in registers: each loop knows which side it adds to
      uint32_t i = r.begin, j = r.end;
      for (;;) {
        for (; i < j; ++i) {
          const __m128 c = refs[i].centroid2();
          if (!isLeft(c)) {
            cr.grow(c);
            break;
          }
          cl.grow(c);
        }
        for (; i < j; --j) {
          const __m128 c = refs[j - 1].centroid2();
          if (isLeft(c)) {
            cl.grow(c);
            break;
          }
          cr.grow(c);
        }
        if (i >= j) break;
        std::swap(refs[i++], refs[--j]);
      }
      s.left.cbounds = cl;
      s.right.cbounds = cr;
      return;
    }
    // In parallel: list the misplaced refs of each side in that order, then swap the k-th pairs.
    const uint32_t mid = s.left.end;
    std::vector<std::vector<uint32_t>> front(chunks), back(chunks);
    std::vector<std::array<Box, 2>> cb(chunks);
    const auto cut = [&](uint32_t b, uint32_t e, uint32_t c) { return b + uint32_t(uint64_t(e - b) * c / chunks); };
    chunked(chunks, [&](uint32_t c) {
      for (uint32_t i = cut(r.begin, mid, c); i < cut(r.begin, mid, c + 1); ++i)
        if (!left(refs[i], cb[c].data())) front[c].push_back(i);
      // Back side from the end: chunk c covers the c-th stretch counted from r.end down.
      for (uint32_t i = r.end - cut(0, r.end - mid, c); i > r.end - cut(0, r.end - mid, c + 1); --i)
        if (left(refs[i - 1], cb[c].data())) back[c].push_back(i - 1);
    });
    for (uint32_t c = 0; c < chunks; ++c) {
      s.left.cbounds.grow(cb[c][0]);
      s.right.cbounds.grow(cb[c][1]);
    }
    std::vector<uint32_t> f, b;
    for (uint32_t c = 0; c < chunks; ++c) {
      f.insert(f.end(), front[c].begin(), front[c].end());
      b.insert(b.end(), back[c].begin(), back[c].end());
    }
    if (f.size() != b.size()) throw Error("BVH build: partition counts disagree with the bins");  // never: same arithmetic
    chunked(chunks, [&](uint32_t c) {
      for (size_t k = size_t(f.size()) * c / chunks; k < size_t(f.size()) * (c + 1) / chunks; ++k)
        std::swap(refs[f[k]], refs[b[k]]);
    });
  }

  static Range boundsOf(const PrimRef* refs, uint32_t b, uint32_t e, uint32_t depth) {
    Range r;
    r.begin = b;
    r.end = e;
    r.depth = depth;
    for (uint32_t i = b; i < e; ++i) {
      r.bounds.grow(refs[i].box());
      r.cbounds.grow(refs[i].centroid2());
    }
    return r;
  }

  // Split a range in two: SAH when it pays, by count when the centroids coincide or the tree is too deep.
  // Returns false when the range should stay a leaf.
  bool split(const Range& r, Range& a, Range& b, uint32_t level) {
    const uint32_t n = r.size();
    if (n <= 1) return false;
    const bool tooDeep = r.depth > 48;
    if (!tooDeep) {
      Split s = findSplit(r, level);
      if (s.axis >= 0) {
        const float leafCost = r.bounds.halfArea() * float(packsFor(n));
        const float splitCost = kNodeCost * r.bounds.halfArea() + s.cost;
        if (n <= Bvh::kMaxLeafTriangles && leafCost <= splitCost) return false;
        partition(s, r, level);
        a = s.left;
        b = s.right;
        return true;
      }
      if (n <= Bvh::kMaxLeafTriangles) return false;
    }
    // Median by count along the widest centroid axis.
    alignas(16) float e[4];
    _mm_store_ps(e, _mm_sub_ps(r.cbounds.hi, r.cbounds.lo));
    const int axis = e[0] >= e[1] && e[0] >= e[2] ? 0 : (e[1] >= e[2] ? 1 : 2);
    const uint32_t mid = r.begin + n / 2;
    std::nth_element(&refs[r.begin], &refs[mid], &refs[r.end], [axis](const PrimRef& p, const PrimRef& q) {
      return lane(p.centroid2(), axis) < lane(q.centroid2(), axis);
    });
    a = boundsOf(refs.get(), r.begin, mid, r.depth + 1);
    b = boundsOf(refs.get(), mid, r.end, r.depth + 1);
    return true;
  }

  // A leaf during the build: kLeafBit | (packs - 1) << 28 | its index in `leaves`.
  uint32_t makeLeaf(const Range& r) {
    const uint32_t np = packsFor(r.size()), index = leafCount.fetch_add(1);
    packCount.fetch_add(np);
    leaves[index] = {r.begin, r.end};
    return Bvh::kLeafBit | ((np - 1) << 28) | index;
  }

  // The packs of the leaf with refs [begin, end), from `out` on.
  void writePacks(std::array<uint32_t, 2> range, TriPack* out) const {
    const auto [begin, end] = range;
    for (uint32_t p = 0; p < packsFor(end - begin); ++p) {
      TriPack& pack = out[p];
      for (uint32_t lane = 0; lane < kWidth; ++lane) {
        const uint32_t i = std::min(begin + p * kWidth + lane, end - 1);  // short packs repeat the last
        const uint32_t id = refs[i].id();
        const Triangle& t = tris[id];
        const glm::vec3* v[3] = {&t.v0, &t.v1, &t.v2};
        for (int k = 0; k < 3; ++k)
          for (int a = 0; a < 3; ++a) pack.v[k][a][lane] = (*v[k])[a];
        pack.prim[lane] = id | (casts.empty() || casts[id] ? 0u : Bvh::kNoShadowBit);
      }
    }
  }

  // Writes the subtree of node `ref` into bvh's arrays in depth-first order, its node at `node`, its packs
  // (made here) from `pack` on: the subtree sizes place every child, so large subtrees are written by the pool.
  void relayout(uint32_t ref, Bvh& bvh, uint32_t node, uint32_t pack, ThreadPool::Group& g) const {
    Node n = nodes[ref];
    uint32_t nextNode = node + 1, nextPack = pack;
    for (int k = 0; k < int(kWidth); ++k) {
      if (!(n.box[0][0][k] <= n.box[1][0][k])) continue;  // empty
      const uint32_t c = n.child[k];
      if (c & Bvh::kLeafBit) {
        writePacks(leaves[c & 0x0FFFFFFFu], &bvh.packs_[nextPack]);
        n.child[k] = (c & ~0x0FFFFFFFu) | nextPack;
        nextPack += ((c >> 28) & 7u) + 1;
        continue;
      }
      n.child[k] = nextNode;
      if (pool && subtree[c][1] * kWidth >= subtreeTask)
        pool->run(g, [this, c, &bvh, nextNode, nextPack, &g] { relayout(c, bvh, nextNode, nextPack, g); });
      else relayout(c, bvh, nextNode, nextPack, g);
      nextNode += subtree[c][0];
      nextPack += subtree[c][1];
    }
    bvh.nodes_[node] = n;
  }

  uint32_t build(const Range& r, uint32_t level = 0) {
    uint32_t d = maxDepth.load();
    while (r.depth > d && !maxDepth.compare_exchange_weak(d, r.depth)) {}
    struct Child {
      Range r;
      bool leaf = false;
    };
    Child c[kWidth];
    int count = 1;
    c[0].r = r;
    Range a, b;
    if (!split(r, a, b, level)) return makeLeaf(r);
    c[0].r = a;
    c[1].r = b;
    count = 2;
    while (count < int(kWidth)) {
      int pick = -1;
      float area = -1.0f;
      for (int i = 0; i < count; ++i)
        if (!c[i].leaf && c[i].r.bounds.halfArea() > area) {
          area = c[i].r.bounds.halfArea();
          pick = i;
        }
      if (pick < 0) break;
      if (!split(c[pick].r, a, b, level)) {
        c[pick].leaf = true;
        continue;
      }
      c[pick].r = a;
      c[count++].r = b;
    }
    const uint32_t index = nodeCount.fetch_add(1);
    Node node;
    for (int k = 0; k < int(kWidth); ++k) {
      for (int a3 = 0; a3 < 3; ++a3) {
        node.box[0][a3][k] = k < count ? lane(c[k].r.bounds.lo, a3) : kInf;
        node.box[1][a3][k] = k < count ? lane(c[k].r.bounds.hi, a3) : -kInf;
      }
      node.child[k] = Bvh::kLeafBit;  // empty slots: a leaf of one pack that the box test never reaches
    }
    // Large subtrees are tasks for the pool, the last one built here; the tree is the same whatever
    // thread builds what (the copy-out orders it).
    ThreadPool::Group g;
    int last = count - 1;
    while (last >= 0 && (c[last].leaf || !pool || c[last].r.size() < subtreeTask)) --last;
    for (int k = 0; k < count; ++k) {
      if (c[k].leaf) node.child[k] = makeLeaf(c[k].r);
      else if (pool && k != last && c[k].r.size() >= subtreeTask)
        pool->run(g, [this, &node, k, rr = c[k].r, level] { node.child[k] = build(rr, level + 1); });
      else node.child[k] = build(c[k].r, level + 1);
    }
    if (pool) pool->wait(g);
    nodes[index] = node;
    std::array<uint32_t, 2> size{1, 0};
    for (int k = 0; k < count; ++k) {
      const uint32_t ch = node.child[k];
      if (ch & Bvh::kLeafBit) size[1] += ((ch >> 28) & 7u) + 1;
      else {
        size[0] += subtree[ch][0];
        size[1] += subtree[ch][1];
      }
    }
    subtree[index] = size;
    return index;
  }
};

Bvh::Bvh(std::span<const Triangle> triangles, std::span<const uint8_t> castsShadow, unsigned threads) {
  const auto start = std::chrono::steady_clock::now();
  if (triangles.size() > kMaxTriangles)
    throw Error("BVH: " + std::to_string(triangles.size()) + " triangles, at most " + std::to_string(kMaxTriangles));
  threads = threadCount(threads);
  BvhBuilder b;
  b.tris = triangles;
  b.casts = castsShadow;
  b.threads = threads;
  std::unique_ptr<ThreadPool> pool;
  if (threads > 1) b.pool = (pool = std::make_unique<ThreadPool>(threads - 1)).get();
  // The references and the root's bounds, by all threads: each chunk of triangles keeps its finite ones
  // at its own start, and the chunks close up after (only where some were left out).
  const uint32_t count = uint32_t(triangles.size());
  b.refs.reset(new PrimRef[std::max(count, 1u)]);
  const uint32_t chunks = std::max(1u, std::min(threads, count / 16384));
  std::vector<uint32_t> kept(chunks);
  std::vector<Range> part(chunks);
  const auto cut = [&](uint32_t c) { return uint32_t(uint64_t(count) * c / chunks); };
  b.chunked(chunks, [&](uint32_t c) {
    uint32_t out = cut(c);
    for (uint32_t i = cut(c); i < cut(c + 1); ++i) {
      const Triangle& t = triangles[i];
      // Triangles with non-finite coordinates can never be hit; keep them out of the boxes. (Each vertex:
      // min and max pass a NaN over when the box already has a number.)
      const auto finite = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
      if (!finite(t.v0) || !finite(t.v1) || !finite(t.v2)) continue;
      Box box;
      box.grow(load3(t.v0));
      box.grow(load3(t.v1));
      box.grow(load3(t.v2));
      const PrimRef& p = b.refs[out++] = {_mm_castsi128_ps(_mm_insert_epi32(_mm_castps_si128(box.lo), int(i), 3)), box.hi};
      part[c].bounds.grow(p.box());
      part[c].cbounds.grow(p.centroid2());
    }
    kept[c] = out - cut(c);
  });
  Range root;
  uint32_t n = 0;
  for (uint32_t c = 0; c < chunks; ++c) {
    if (n != cut(c)) std::memmove(&b.refs[n], &b.refs[cut(c)], kept[c] * sizeof(PrimRef));
    n += kept[c];
    root.bounds.grow(part[c].bounds);
    root.cbounds.grow(part[c].cbounds);
  }
  root.end = n;
  stats_.triangles = n;
  if (n == 0) return;
  b.nodes.reset(new Node[n + 1]);
  b.leaves.reset(new std::array<uint32_t, 2>[n + 1]);
  b.subtree.reset(new std::array<uint32_t, 2>[n + 1]);
  const auto since = [](auto t) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count(); };
  stats_.refSeconds = since(start);
  const auto treeStart = std::chrono::steady_clock::now();
  root_ = b.build(root);
  stats_.treeSeconds = since(treeStart);
  // Copy out in depth-first order (the parallel build interleaved the subtrees of its threads), the packs
  // written once, in place: 40 bytes a triangle less to write, read and fault in.
  nodes_ = HugeArray<Node>(b.nodeCount.load());
  packs_ = HugeArray<TriPack>(b.packCount.load());
  if (root_ & kLeafBit) {
    b.writePacks(b.leaves[0], &packs_[0]);
    root_ &= ~0x0FFFFFFFu;
  } else {
    ThreadPool::Group g;
    b.relayout(root_, *this, 0, 0, g);
    if (b.pool) b.pool->wait(g);
    root_ = 0;
  }
  stats_.nodes = uint32_t(nodes_.size());
  stats_.packs = uint32_t(packs_.size());
  stats_.maxDepth = b.maxDepth.load();
  stats_.buildSeconds = since(start);
}

double Bvh::sahCost() const { return empty() ? 0.0 : treeSahCost(nodes_.data(), root_); }

template <class T>
HugeArray<T>::HugeArray(size_t n) : n_(n) {
  constexpr size_t kHuge = size_t(2) << 20;
  size_t bytes = std::max<size_t>(n, 1) * sizeof(T);
  const size_t align = bytes >= kHuge ? kHuge : alignof(T);
  bytes = (bytes + align - 1) / align * align;
  void* p = std::aligned_alloc(align, bytes);
  if (!p) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
  if (align == kHuge) madvise(p, bytes, MADV_HUGEPAGE);  // a hint: without THP it is plain pages
#endif
  p_.reset(static_cast<T*>(p));
}

template <class T>
void HugeArray<T>::Free::operator()(T* p) const {
  std::free(p);
}

template class HugeArray<Node>;
template class HugeArray<TriPack>;

#define RTR_DECLARE_TRAVERSAL(ns)                                                              \
  namespace ns {                                                                               \
  bool closest(const Bvh::View&, const Ray&, IntersectMethod, Hit&);                           \
  bool occluded(const Bvh::View&, const Ray&, IntersectMethod, Hit&);                          \
  unsigned closestPair(const Bvh::View&, const Ray*, IntersectMethod, Hit*);                   \
  unsigned occludedPair(const Bvh::View&, const Ray*, IntersectMethod, Hit*);                  \
  unsigned closestPacket(const Bvh::View&, const Ray*, int, IntersectMethod, Hit*, int, int);  \
  unsigned occludedPacket(const Bvh::View&, const Ray*, int, IntersectMethod, Hit*, int, int); \
  }
RTR_DECLARE_TRAVERSAL(sse)
RTR_DECLARE_TRAVERSAL(avx2)
RTR_DECLARE_TRAVERSAL(avx512)
RTR_DECLARE_TRAVERSAL(counted)
#undef RTR_DECLARE_TRAVERSAL

namespace {
// The traversals by BvhIsa.
struct Traversal {
  bool (*closest)(const Bvh::View&, const Ray&, IntersectMethod, Hit&);
  bool (*occluded)(const Bvh::View&, const Ray&, IntersectMethod, Hit&);
  unsigned (*closestPair)(const Bvh::View&, const Ray*, IntersectMethod, Hit*);
  unsigned (*occludedPair)(const Bvh::View&, const Ray*, IntersectMethod, Hit*);
  unsigned (*closestPacket)(const Bvh::View&, const Ray*, int, IntersectMethod, Hit*, int, int);
  unsigned (*occludedPacket)(const Bvh::View&, const Ray*, int, IntersectMethod, Hit*, int, int);
};
#define RTR_TRAVERSAL(ns) \
  { ns::closest, ns::occluded, ns::closestPair, ns::occludedPair, ns::closestPacket, ns::occludedPacket }
constexpr Traversal kTraversals[] = {RTR_TRAVERSAL(sse), RTR_TRAVERSAL(avx2), RTR_TRAVERSAL(avx512)};
constexpr Traversal kCounted = RTR_TRAVERSAL(counted);
std::atomic<bool> counting{false};
std::atomic<int> packetLeafRays{Bvh::kPacketLeafRays};
std::atomic<int> packetAloneRays[3] = {Bvh::kPacketAloneRays[0], Bvh::kPacketAloneRays[1], Bvh::kPacketAloneRays[2]};
int aloneRays(int kind) { return packetAloneRays[kind].load(std::memory_order_relaxed); }
thread_local BvhCounters threadCounters;
#undef RTR_TRAVERSAL
}  // namespace

namespace {
bool cpuHas(BvhIsa isa) {
  __builtin_cpu_init();  // may run before libgcc's own initialiser (static initialisation order)
  switch (isa) {
    case BvhIsa::Sse: return true;
    case BvhIsa::Avx2: return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    case BvhIsa::Avx512:
      return cpuHas(BvhIsa::Avx2) && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
             __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
  }
  return false;
}
BvhIsa best(BvhIsa wanted) {
  for (BvhIsa isa : {BvhIsa::Avx512, BvhIsa::Avx2})
    if (int(isa) <= int(wanted) && cpuHas(isa)) return isa;
  return BvhIsa::Sse;
}
std::atomic<BvhIsa> currentIsa{best(BvhIsa::Avx512)};
}  // namespace

BvhIsa Bvh::setIsa(BvhIsa isa) {
  currentIsa = best(isa);
  return currentIsa;
}

BvhIsa Bvh::isa() { return currentIsa.load(std::memory_order_relaxed); }

void Bvh::setCounting(bool on) { counting = on && cpuHas(BvhIsa::Avx2); }
void Bvh::setPacketLeafRays(int n) { packetLeafRays = n; }
void Bvh::setPacketAloneRays(int coherent, int scattered, int shadow) {
  packetAloneRays[0] = coherent;
  packetAloneRays[1] = scattered;
  packetAloneRays[2] = shadow;
}
BvhCounters& Bvh::counters() { return threadCounters; }

namespace {
const Traversal& traversal() { return counting.load(std::memory_order_relaxed) ? kCounted : kTraversals[int(Bvh::isa())]; }
}  // namespace

const char* Bvh::isaName(BvhIsa isa) {
  switch (isa) {
    case BvhIsa::Sse: return "SSE4.2";
    case BvhIsa::Avx2: return "AVX2";
    case BvhIsa::Avx512: return "AVX-512VL";
  }
  return "?";
}

Hit Bvh::closest(const Ray& ray, IntersectMethod method) const {
  Hit h;
  if (root_ == kEmpty) return h;
  traversal().closest({nodes_.data(), packs_.data(), root_}, ray, method, h);
  return h;
}

bool Bvh::occluded(const Ray& ray, IntersectMethod method) const {
  Hit h;
  if (root_ == kEmpty) return false;
  return traversal().occluded({nodes_.data(), packs_.data(), root_}, ray, method, h);
}

std::array<Hit, 2> Bvh::closestPair(const std::array<Ray, 2>& rays, IntersectMethod method) const {
  std::array<Hit, 2> h;
  if (root_ != kEmpty) traversal().closestPair({nodes_.data(), packs_.data(), root_}, rays.data(), method, h.data());
  return h;
}

std::array<bool, 2> Bvh::occludedPair(const std::array<Ray, 2>& rays, IntersectMethod method) const {
  std::array<Hit, 2> h;
  if (root_ == kEmpty) return {false, false};
  const unsigned m = traversal().occludedPair({nodes_.data(), packs_.data(), root_}, rays.data(), method, h.data());
  return {(m & 1) != 0, (m & 2) != 0};
}

void Bvh::closest8(const Ray* rays, int n, Hit* hits, IntersectMethod method, PacketKind kind) const {
  for (int i = 0; i < n; ++i) hits[i] = Hit{};
  if (root_ == kEmpty || n <= 0) return;
  if (n == 1) {
    hits[0] = closest(rays[0], method);
    return;
  }
  const Traversal& tr = traversal();
  const View v{nodes_.data(), packs_.data(), root_};
  // Rays with a near-tie between two candidates are traced again alone (bvh_packet.inl).
  for (unsigned retry = tr.closestPacket(v, rays, std::min(n, 8), method, hits, packetLeafRays.load(std::memory_order_relaxed),
                                         aloneRays(int(kind)));
       retry; retry &= retry - 1) {
    const int i = __builtin_ctz(retry);
    if (&tr == &kCounted) ++threadCounters.retries;
    hits[i] = Hit{};
    tr.closest(v, rays[i], method, hits[i]);
  }
}

unsigned Bvh::occluded8(const Ray* rays, int n, IntersectMethod method) const {
  if (root_ == kEmpty || n <= 0) return 0;
  if (n == 1) return unsigned(occluded(rays[0], method));
  Hit scratch[8];
  return traversal().occludedPacket({nodes_.data(), packs_.data(), root_}, rays, std::min(n, 8), method, scratch,
                                    packetLeafRays.load(std::memory_order_relaxed), aloneRays(2));
}

}  // namespace rtr::trace
