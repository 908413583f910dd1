#include "trace/bvh.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <memory>
#include <thread>

#include <immintrin.h>

#include <glm/common.hpp>

namespace rtr::trace {
namespace {

constexpr int kBins = 16;
constexpr float kInf = std::numeric_limits<float>::infinity();

struct Box {
  glm::vec3 lo{kInf}, hi{-kInf};
  void grow(const glm::vec3& p) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
  void grow(const Box& b) { lo = glm::min(lo, b.lo); hi = glm::max(hi, b.hi); }
  float halfArea() const {
    const glm::vec3 e = glm::max(hi - lo, glm::vec3(0.0f));
    return e.x * e.y + e.y * e.z + e.z * e.x;
  }
};

struct PrimRef {
  Box box;
  uint32_t id;
  glm::vec3 centroid2() const { return box.lo + box.hi; }  // twice the centroid: saves a multiply
};

struct Range {
  uint32_t begin = 0, end = 0;
  Box bounds, cbounds;  // of the triangles, and of their (doubled) centroids
  uint32_t depth = 0;
  uint32_t size() const { return end - begin; }
};

uint32_t packsFor(uint32_t n) { return (n + 3) / 4; }

}  // namespace

// Top-down build straight into 4-wide nodes: a node's range is split by binned SAH, and the child with
// the largest area is split again until there are four, as in Wald 2007 / Embree's BVH4 builder.
struct BvhBuilder {
  std::span<const Triangle> tris;
  std::span<const uint8_t> casts;
  std::vector<PrimRef> refs;
  std::unique_ptr<Node4[]> nodes;
  std::unique_ptr<TriPack[]> packs;
  std::atomic<uint32_t> nodeCount{0}, packCount{0}, maxDepth{0};
  std::atomic<int> spawnBudget{0};

  struct Split {
    int axis = -1, bin = 0;
    float cost = kInf;
    Range left, right;
  };

  // Binned SAH over all three axes in one pass. Cost counts packs of four, since a leaf's price is the
  // number of 4-wide triangle tests it takes.
  Split findSplit(const Range& r) const {
    struct Bin { Box b, c; uint32_t n = 0; };
    Bin bins[3][kBins];
    const glm::vec3 ext = r.cbounds.hi - r.cbounds.lo;
    glm::vec3 scale;
    for (int a = 0; a < 3; ++a) scale[a] = ext[a] > 0.0f ? float(kBins) * 0.99999f / ext[a] : 0.0f;
    for (uint32_t i = r.begin; i < r.end; ++i) {
      const PrimRef& p = refs[i];
      const glm::vec3 c = p.centroid2();
      for (int a = 0; a < 3; ++a) {
        const int k = std::clamp(int((c[a] - r.cbounds.lo[a]) * scale[a]), 0, kBins - 1);
        Bin& bin = bins[a][k];
        bin.b.grow(p.box);
        bin.c.grow(c);
        ++bin.n;
      }
    }
    Split best;
    for (int a = 0; a < 3; ++a) {
      if (!(ext[a] > 0.0f)) continue;
      float rightCost[kBins];
      Box acc;
      uint32_t n = 0;
      for (int k = kBins - 1; k > 0; --k) {
        acc.grow(bins[a][k].b);
        n += bins[a][k].n;
        rightCost[k] = acc.halfArea() * float(packsFor(n));
      }
      acc = Box{};
      n = 0;
      for (int k = 0; k < kBins - 1; ++k) {
        acc.grow(bins[a][k].b);
        n += bins[a][k].n;
        if (n == 0 || n == r.size()) continue;
        const float cost = acc.halfArea() * float(packsFor(n)) + rightCost[k + 1];
        if (cost < best.cost) { best.cost = cost; best.axis = a; best.bin = k; }
      }
    }
    if (best.axis < 0) return best;
    // Child ranges' bounds straight from the bins.
    Range L, R;
    uint32_t nl = 0;
    for (int k = 0; k < kBins; ++k) {
      const Bin& bin = bins[best.axis][k];
      Range& side = k <= best.bin ? L : R;
      side.bounds.grow(bin.b);
      side.cbounds.grow(bin.c);
      if (k <= best.bin) nl += bin.n;
    }
    L.begin = r.begin; L.end = r.begin + nl; R.begin = L.end; R.end = r.end;
    L.depth = R.depth = r.depth + 1;
    best.left = L;
    best.right = R;
    return best;
  }

  void partition(const Split& s, const Range& r) {
    const int a = s.axis;
    const float lo = r.cbounds.lo[a];
    const float ext = r.cbounds.hi[a] - lo;
    const float scale = float(kBins) * 0.99999f / ext;
    std::partition(refs.begin() + r.begin, refs.begin() + r.end, [&](const PrimRef& p) {
      return std::clamp(int((p.centroid2()[a] - lo) * scale), 0, kBins - 1) <= s.bin;
    });
  }

  static Range boundsOf(const std::vector<PrimRef>& refs, uint32_t b, uint32_t e, uint32_t depth) {
    Range r;
    r.begin = b; r.end = e; r.depth = depth;
    for (uint32_t i = b; i < e; ++i) { r.bounds.grow(refs[i].box); r.cbounds.grow(refs[i].centroid2()); }
    return r;
  }

  // Split a range in two: SAH when it pays, by count when the centroids coincide or the tree is too deep.
  // Returns false when the range should stay a leaf.
  bool split(const Range& r, Range& a, Range& b) {
    const uint32_t n = r.size();
    if (n <= 4) return false;  // one pack: nothing to gain
    const bool tooDeep = r.depth > 48;
    if (!tooDeep) {
      const Split s = findSplit(r);
      if (s.axis >= 0) {
        const float leafCost = r.bounds.halfArea() * float(packsFor(n));
        const float splitCost = 0.5f * r.bounds.halfArea() + s.cost;  // a box test costs ~half a pack
        if (n <= Bvh::kMaxLeafTriangles && leafCost <= splitCost) return false;
        partition(s, r);
        a = s.left;
        b = s.right;
        return true;
      }
      if (n <= Bvh::kMaxLeafTriangles) return false;
    }
    // Median by count along the widest centroid axis.
    const glm::vec3 e = r.cbounds.hi - r.cbounds.lo;
    const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    const uint32_t mid = r.begin + n / 2;
    std::nth_element(refs.begin() + r.begin, refs.begin() + mid, refs.begin() + r.end,
                     [axis](const PrimRef& p, const PrimRef& q) { return p.centroid2()[axis] < q.centroid2()[axis]; });
    a = boundsOf(refs, r.begin, mid, r.depth + 1);
    b = boundsOf(refs, mid, r.end, r.depth + 1);
    return true;
  }

  uint32_t makeLeaf(const Range& r) {
    const uint32_t n = r.size(), np = packsFor(n);
    const uint32_t first = packCount.fetch_add(np);
    for (uint32_t p = 0; p < np; ++p) {
      TriPack& pack = packs[first + p];
      pack.occluderMask = 0;
      pack.pad[0] = pack.pad[1] = pack.pad[2] = 0;
      for (uint32_t lane = 0; lane < 4; ++lane) {
        const uint32_t i = std::min(r.begin + p * 4 + lane, r.end - 1);  // short packs repeat the last
        const uint32_t id = refs[i].id;
        const Triangle& t = tris[id];
        const glm::vec3* v[3] = {&t.v0, &t.v1, &t.v2};
        for (int k = 0; k < 3; ++k)
          for (int a = 0; a < 3; ++a) pack.v[k][a][lane] = (*v[k])[a];
        pack.prim[lane] = id;
        if (casts.empty() || casts[id]) pack.occluderMask |= 1u << lane;
      }
    }
    return Bvh::kLeafBit | ((np - 1) << 28) | first;
  }

  uint32_t build(const Range& r) {
    uint32_t d = maxDepth.load();
    while (r.depth > d && !maxDepth.compare_exchange_weak(d, r.depth)) {}
    struct Child { Range r; bool leaf = false; };
    Child c[4];
    int count = 1;
    c[0].r = r;
    Range a, b;
    if (!split(r, a, b)) return makeLeaf(r);
    c[0].r = a;
    c[1].r = b;
    count = 2;
    while (count < 4) {
      int pick = -1;
      float area = -1.0f;
      for (int i = 0; i < count; ++i)
        if (!c[i].leaf && c[i].r.bounds.halfArea() > area) { area = c[i].r.bounds.halfArea(); pick = i; }
      if (pick < 0) break;
      if (!split(c[pick].r, a, b)) { c[pick].leaf = true; continue; }
      c[pick].r = a;
      c[count++].r = b;
    }
    const uint32_t index = nodeCount.fetch_add(1);
    Node4 node;
    for (int k = 0; k < 4; ++k) {
      for (int a3 = 0; a3 < 3; ++a3) {
        node.box[0][a3][k] = k < count ? c[k].r.bounds.lo[a3] : kInf;
        node.box[1][a3][k] = k < count ? c[k].r.bounds.hi[a3] : -kInf;
      }
      node.child[k] = Bvh::kLeafBit;  // empty slots: a leaf of one pack that the box test never reaches
    }
    std::future<uint32_t> pending[4];
    for (int k = 0; k < count; ++k) {
      if (c[k].leaf) { node.child[k] = makeLeaf(c[k].r); continue; }
      if (c[k].r.size() > 20000 && spawnBudget.fetch_sub(1) > 0)
        pending[k] = std::async(std::launch::async, [this, rr = c[k].r] { return build(rr); });
      else
        node.child[k] = build(c[k].r);
    }
    for (int k = 0; k < count; ++k)
      if (pending[k].valid()) node.child[k] = pending[k].get();
    nodes[index] = node;
    return index;
  }
};

Bvh::Bvh(std::span<const Triangle> triangles, std::span<const uint8_t> castsShadow, unsigned threads) {
  const auto start = std::chrono::steady_clock::now();
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  BvhBuilder b;
  b.tris = triangles;
  b.casts = castsShadow;
  b.refs.reserve(triangles.size());
  for (uint32_t i = 0; i < triangles.size(); ++i) {
    const Triangle& t = triangles[i];
    PrimRef p;
    p.box.grow(t.v0); p.box.grow(t.v1); p.box.grow(t.v2);
    p.id = i;
    // Triangles with non-finite coordinates can never be hit; keep them out of the boxes.
    bool finite = true;
    for (int a = 0; a < 3; ++a) finite = finite && std::isfinite(p.box.lo[a]) && std::isfinite(p.box.hi[a]);
    if (!finite) continue;
    b.refs.push_back(p);
  }
  const uint32_t n = uint32_t(b.refs.size());
  stats_.triangles = n;
  if (n == 0) return;
  b.nodes.reset(new Node4[n + 1]);
  b.packs.reset(new TriPack[n + 1]);
  b.spawnBudget = int(threads) * 2 - 1;
  root_ = b.build(BvhBuilder::boundsOf(b.refs, 0, n, 0));
  nodes_.assign(b.nodes.get(), b.nodes.get() + b.nodeCount.load());
  packs_.assign(b.packs.get(), b.packs.get() + b.packCount.load());
  stats_.nodes = uint32_t(nodes_.size());
  stats_.packs = uint32_t(packs_.size());
  stats_.maxDepth = b.maxDepth.load();
  stats_.buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

namespace {

inline Triangle laneTriangle(const TriPack& p, int lane) {
  return {{p.v[0][0][lane], p.v[0][1][lane], p.v[0][2][lane]},
          {p.v[1][0][lane], p.v[1][1][lane], p.v[1][2][lane]},
          {p.v[2][0][lane], p.v[2][1][lane], p.v[2][2][lane]}};
}

// 1 + 2·gamma(3): scaling a slab's far distance by it makes the box test conservative under rounding
// (Ize 2013), which the watertight triangle test needs to stay watertight inside the BVH.
constexpr float kFarScale = 1.0f + 2.0f * (3.0f * 0x1p-24f) / (1.0f - 3.0f * 0x1p-24f);

}  // namespace

template <bool AnyHit>
bool Bvh::traverse(const Ray& ray, IntersectMethod method, Hit& hit) const {
  if (root_ == kEmpty) return false;
  const WatertightRay wr(ray);
  __m128 org[3], rdir[3];
  int nearIdx[3];
  for (int a = 0; a < 3; ++a) {
    // A zero component gives an infinite reciprocal and, on the slab's plane, 0·inf = NaN: the min/max
    // below are ordered so that a NaN slab distance is ignored (SSE min/max return the second operand).
    const float inv = 1.0f / ray.direction[a];
    org[a] = _mm_set1_ps(ray.origin[a]);
    rdir[a] = _mm_set1_ps(inv);
    nearIdx[a] = inv < 0.0f ? 1 : 0;
  }
  float tHit = ray.tMax;
  const __m128 farScale = _mm_set1_ps(kFarScale), zero = _mm_setzero_ps();
  const __m128 signBit = _mm_set1_ps(-0.0f);
  const __m128 sx = _mm_set1_ps(wr.sx), sy = _mm_set1_ps(wr.sy), sz = _mm_set1_ps(wr.sz);
  const int kx = wr.kx, ky = wr.ky, kz = wr.kz;

  struct Entry { uint32_t ref; float t; };
  Entry stack[256];
  int sp = 0;
  uint32_t ref = root_;
  bool found = false;

  for (;;) {
    const __m128 tHitV = _mm_set1_ps(tHit);
    while (!(ref & kLeafBit)) {
      const Node4& n = nodes_[ref];
      const __m128 tx0 = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(n.box[nearIdx[0]][0]), org[0]), rdir[0]);
      const __m128 ty0 = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(n.box[nearIdx[1]][1]), org[1]), rdir[1]);
      const __m128 tz0 = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(n.box[nearIdx[2]][2]), org[2]), rdir[2]);
      const __m128 tx1 = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(n.box[1 - nearIdx[0]][0]), org[0]), rdir[0]);
      const __m128 ty1 = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(n.box[1 - nearIdx[1]][1]), org[1]), rdir[1]);
      const __m128 tz1 = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(n.box[1 - nearIdx[2]][2]), org[2]), rdir[2]);
      const __m128 tNear = _mm_max_ps(tz0, _mm_max_ps(ty0, _mm_max_ps(tx0, zero)));
      const __m128 tFar = _mm_min_ps(_mm_mul_ps(tz1, farScale),
                                     _mm_min_ps(_mm_mul_ps(ty1, farScale), _mm_min_ps(_mm_mul_ps(tx1, farScale), tHitV)));
      unsigned mask = unsigned(_mm_movemask_ps(_mm_cmple_ps(tNear, tFar)));
      if (mask == 0) goto pop;
      alignas(16) float dist[4];
      _mm_store_ps(dist, tNear);
      if constexpr (AnyHit) {
        ref = n.child[std::countr_zero(mask)];
        for (mask &= mask - 1; mask; mask &= mask - 1) stack[sp++] = {n.child[std::countr_zero(mask)], 0.0f};
        continue;
      } else {
        const int c0 = std::countr_zero(mask);
        mask &= mask - 1;
        if (mask == 0) { ref = n.child[c0]; continue; }
        // Two or more: push all but the nearest, farthest first, so the stack pops front to back.
        Entry e[4];
        int m = 0;
        e[m++] = {n.child[c0], dist[c0]};
        for (; mask; mask &= mask - 1) {
          const int c = std::countr_zero(mask);
          Entry x{n.child[c], dist[c]};
          int j = m++;
          while (j > 0 && e[j - 1].t < x.t) { e[j] = e[j - 1]; --j; }
          e[j] = x;
        }
        for (int j = 0; j < m - 1; ++j) stack[sp++] = e[j];
        ref = e[m - 1].ref;
        continue;
      }
    }
    {
      // Leaf: its packs of four triangles.
      const uint32_t first = ref & 0x0FFFFFFFu, np = ((ref >> 28) & 7u) + 1;
      for (uint32_t p = first; p < first + np; ++p) {
        const TriPack& pk = packs_[p];
        if (method != IntersectMethod::Watertight) {
          for (int lane = 0; lane < 4; ++lane) {
            if (AnyHit && !(pk.occluderMask >> lane & 1u)) continue;
            Ray r = ray;
            r.tMax = tHit;
            float b1, b2;
            const float t = intersect(method, r, laneTriangle(pk, lane), b1, b2);
            if (t > 0.0f) {
              if constexpr (AnyHit) return true;
              tHit = t; hit = {t, b1, b2, pk.prim[lane]}; found = true;
            }
          }
          continue;
        }
        const __m128 A[3] = {_mm_sub_ps(_mm_load_ps(pk.v[0][0]), org[0]), _mm_sub_ps(_mm_load_ps(pk.v[0][1]), org[1]),
                             _mm_sub_ps(_mm_load_ps(pk.v[0][2]), org[2])};
        const __m128 B[3] = {_mm_sub_ps(_mm_load_ps(pk.v[1][0]), org[0]), _mm_sub_ps(_mm_load_ps(pk.v[1][1]), org[1]),
                             _mm_sub_ps(_mm_load_ps(pk.v[1][2]), org[2])};
        const __m128 C[3] = {_mm_sub_ps(_mm_load_ps(pk.v[2][0]), org[0]), _mm_sub_ps(_mm_load_ps(pk.v[2][1]), org[1]),
                             _mm_sub_ps(_mm_load_ps(pk.v[2][2]), org[2])};
        const __m128 ax = _mm_sub_ps(A[kx], _mm_mul_ps(sx, A[kz])), ay = _mm_sub_ps(A[ky], _mm_mul_ps(sy, A[kz]));
        const __m128 bx = _mm_sub_ps(B[kx], _mm_mul_ps(sx, B[kz])), by = _mm_sub_ps(B[ky], _mm_mul_ps(sy, B[kz]));
        const __m128 cx = _mm_sub_ps(C[kx], _mm_mul_ps(sx, C[kz])), cy = _mm_sub_ps(C[ky], _mm_mul_ps(sy, C[kz]));
        const __m128 U = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
        const __m128 V = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
        const __m128 W = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
        const __m128 geq = _mm_and_ps(_mm_and_ps(_mm_cmpge_ps(U, zero), _mm_cmpge_ps(V, zero)), _mm_cmpge_ps(W, zero));
        const __m128 leq = _mm_and_ps(_mm_and_ps(_mm_cmple_ps(U, zero), _mm_cmple_ps(V, zero)), _mm_cmple_ps(W, zero));
        unsigned inside = unsigned(_mm_movemask_ps(_mm_or_ps(geq, leq)));
        if (inside == 0) continue;
        const unsigned onEdge = unsigned(_mm_movemask_ps(
            _mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(U, zero), _mm_cmpeq_ps(V, zero)), _mm_cmpeq_ps(W, zero))));
        const __m128 det = _mm_add_ps(_mm_add_ps(U, V), W);
        const __m128 T = _mm_add_ps(_mm_add_ps(_mm_mul_ps(U, _mm_mul_ps(sz, A[kz])), _mm_mul_ps(V, _mm_mul_ps(sz, B[kz]))),
                                    _mm_mul_ps(W, _mm_mul_ps(sz, C[kz])));
        const __m128 detSign = _mm_and_ps(det, signBit);
        const __m128 Ts = _mm_xor_ps(T, detSign), detAbs = _mm_xor_ps(det, detSign);
        const __m128 ok = _mm_and_ps(_mm_and_ps(_mm_cmpneq_ps(det, zero), _mm_cmpgt_ps(Ts, zero)),
                                     _mm_cmplt_ps(Ts, _mm_mul_ps(_mm_set1_ps(tHit), detAbs)));
        unsigned m = inside & unsigned(_mm_movemask_ps(ok)) & ~onEdge;
        unsigned edge = onEdge;  // exactly on an edge in float: the scalar routine decides in double
        if constexpr (AnyHit) {
          m &= pk.occluderMask;
          edge &= pk.occluderMask;
          if (m) return true;
        }
        if (m) {
          alignas(16) float tv[4], dv[4], vv[4], wv[4];
          _mm_store_ps(tv, T); _mm_store_ps(dv, det); _mm_store_ps(vv, V); _mm_store_ps(wv, W);
          for (; m; m &= m - 1) {
            const int lane = std::countr_zero(m);
            const float inv = 1.0f / dv[lane];
            const float t = tv[lane] * inv;
            if (t > 0.0f && t < tHit) { tHit = t; hit = {t, vv[lane] * inv, wv[lane] * inv, pk.prim[lane]}; found = true; }
          }
        }
        for (; edge; edge &= edge - 1) {
          const int lane = std::countr_zero(edge);
          WatertightRay r = wr;
          r.tMax = tHit;
          float b1, b2;
          const float t = intersectWatertight(r, laneTriangle(pk, lane), b1, b2);
          if (t > 0.0f) {
            if constexpr (AnyHit) return true;
            tHit = t; hit = {t, b1, b2, pk.prim[lane]}; found = true;
          }
        }
      }
    }
  pop:
    for (;;) {
      if (sp == 0) return found;
      const Entry e = stack[--sp];
      if (!AnyHit && e.t > tHit) continue;
      ref = e.ref;
      break;
    }
  }
}

Hit Bvh::closest(const Ray& ray, IntersectMethod method) const {
  Hit h;
  traverse<false>(ray, method, h);
  return h;
}

bool Bvh::occluded(const Ray& ray, IntersectMethod method) const {
  Hit h;
  return traverse<true>(ray, method, h);
}

}  // namespace rtr::trace
