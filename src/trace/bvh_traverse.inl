// BVH traversal, compiled once per instruction set: bvh_sse.cpp, bvh_avx2.cpp and bvh_avx512.cpp include
// this with RTR_BVH_ISA naming the namespace (sse, avx2, avx512) and RTR_BVH_AVX2 set for 8-wide registers.
// Everything here is inline and inside that namespace, and uses no glm or std function templates: an
// out-of-line copy compiled for AVX2 must never be what the SSE build links to.
#include <immintrin.h>

#include <cstring>

#include "trace/bvh.hpp"

namespace rtr::trace::RTR_BVH_ISA {
namespace {

// Eight floats: one AVX register, or two SSE ones with the same per-lane results.
#if RTR_BVH_AVX2
struct F {
  __m256 v;
};
inline F load(const float* p) { return {_mm256_load_ps(p)}; }
inline F set1(float x) { return {_mm256_set1_ps(x)}; }
inline F operator+(F a, F b) { return {_mm256_add_ps(a.v, b.v)}; }
inline F operator-(F a, F b) { return {_mm256_sub_ps(a.v, b.v)}; }
inline F operator*(F a, F b) { return {_mm256_mul_ps(a.v, b.v)}; }
inline F operator/(F a, F b) { return {_mm256_div_ps(a.v, b.v)}; }
inline F operator&(F a, F b) { return {_mm256_and_ps(a.v, b.v)}; }
inline F operator|(F a, F b) { return {_mm256_or_ps(a.v, b.v)}; }
inline F operator^(F a, F b) { return {_mm256_xor_ps(a.v, b.v)}; }
// min/max return the second operand when either is NaN, as the SSE instructions do.
inline F vmin(F a, F b) { return {_mm256_min_ps(a.v, b.v)}; }
inline F vmax(F a, F b) { return {_mm256_max_ps(a.v, b.v)}; }
inline F lt(F a, F b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_LT_OQ)}; }
inline F le(F a, F b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_LE_OQ)}; }
inline F gt(F a, F b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_GT_OQ)}; }
inline F ge(F a, F b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_GE_OQ)}; }
inline F eq(F a, F b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_EQ_OQ)}; }
inline F neq(F a, F b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_NEQ_UQ)}; }
inline F ngt(F a, F b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_NGT_UQ)}; }  // true when unordered
// Max and min of the floats' bit patterns as signed integers (one cycle, not four, on Intel): the same as
// the float max/min when one operand is ≥ +0, see the box test.
inline F imax(F a, F b) { return {_mm256_castsi256_ps(_mm256_max_epi32(_mm256_castps_si256(a.v), _mm256_castps_si256(b.v)))}; }
inline F imin(F a, F b) { return {_mm256_castsi256_ps(_mm256_min_epi32(_mm256_castps_si256(a.v), _mm256_castps_si256(b.v)))}; }
inline unsigned bits(F a) { return unsigned(_mm256_movemask_ps(a.v)); }
template <int Lane>
inline F lane(__m128 v) {
  return {_mm256_broadcastss_ps(_mm_shuffle_ps(v, v, _MM_SHUFFLE(Lane, Lane, Lane, Lane)))};
}
inline void store(float* p, F a) { _mm256_store_ps(p, a.v); }
inline F fmsub(F a, F b, F c) { return {_mm256_fmsub_ps(a.v, b.v, c.v)}; }  // a·b − c, rounded once
// The top bits of eight 32-bit integers.
inline unsigned topBits(const uint32_t* p) {
  return unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_load_si256(reinterpret_cast<const __m256i*>(p)))));
}
#else
struct F {
  __m128 a, b;
};
inline F load(const float* p) { return {_mm_load_ps(p), _mm_load_ps(p + 4)}; }
inline F set1(float x) { return {_mm_set1_ps(x), _mm_set1_ps(x)}; }
inline F operator+(F x, F y) { return {_mm_add_ps(x.a, y.a), _mm_add_ps(x.b, y.b)}; }
inline F operator-(F x, F y) { return {_mm_sub_ps(x.a, y.a), _mm_sub_ps(x.b, y.b)}; }
inline F operator*(F x, F y) { return {_mm_mul_ps(x.a, y.a), _mm_mul_ps(x.b, y.b)}; }
inline F operator/(F x, F y) { return {_mm_div_ps(x.a, y.a), _mm_div_ps(x.b, y.b)}; }
inline F operator&(F x, F y) { return {_mm_and_ps(x.a, y.a), _mm_and_ps(x.b, y.b)}; }
inline F operator|(F x, F y) { return {_mm_or_ps(x.a, y.a), _mm_or_ps(x.b, y.b)}; }
inline F operator^(F x, F y) { return {_mm_xor_ps(x.a, y.a), _mm_xor_ps(x.b, y.b)}; }
inline F vmin(F x, F y) { return {_mm_min_ps(x.a, y.a), _mm_min_ps(x.b, y.b)}; }
inline F vmax(F x, F y) { return {_mm_max_ps(x.a, y.a), _mm_max_ps(x.b, y.b)}; }
inline F lt(F x, F y) { return {_mm_cmplt_ps(x.a, y.a), _mm_cmplt_ps(x.b, y.b)}; }
inline F le(F x, F y) { return {_mm_cmple_ps(x.a, y.a), _mm_cmple_ps(x.b, y.b)}; }
inline F gt(F x, F y) { return {_mm_cmpgt_ps(x.a, y.a), _mm_cmpgt_ps(x.b, y.b)}; }
inline F ge(F x, F y) { return {_mm_cmpge_ps(x.a, y.a), _mm_cmpge_ps(x.b, y.b)}; }
inline F eq(F x, F y) { return {_mm_cmpeq_ps(x.a, y.a), _mm_cmpeq_ps(x.b, y.b)}; }
inline F neq(F x, F y) { return {_mm_cmpneq_ps(x.a, y.a), _mm_cmpneq_ps(x.b, y.b)}; }
inline F ngt(F x, F y) { return {_mm_cmpngt_ps(x.a, y.a), _mm_cmpngt_ps(x.b, y.b)}; }
inline unsigned bits(F x) { return unsigned(_mm_movemask_ps(x.a)) | unsigned(_mm_movemask_ps(x.b)) << 4; }
inline void store(float* p, F x) {
  _mm_store_ps(p, x.a);
  _mm_store_ps(p + 4, x.b);
}
inline unsigned topBits(const uint32_t* p) {
  const __m128i* q = reinterpret_cast<const __m128i*>(p);
  return unsigned(_mm_movemask_ps(_mm_castsi128_ps(_mm_load_si128(q)))) |
         unsigned(_mm_movemask_ps(_mm_castsi128_ps(_mm_load_si128(q + 1)))) << 4;
}
#endif

// The box test's min/max: on the bit patterns as integers where RTR_BVH_INT_MINMAX is set (the AVX-512
// build: on Intel, vmaxps takes several cycles where the integer form takes one), as floats elsewhere (on
// AMD, vmaxps is as quick and the integer unit adds a bypass: measured slower, docs/bench/trace.md).
#if RTR_BVH_INT_MINMAX
inline F slabMax(F a, F b) { return imax(a, b); }
inline F slabMin(F a, F b) { return imin(a, b); }
#else
inline F slabMax(F a, F b) { return vmax(a, b); }
inline F slabMin(F a, F b) { return vmin(a, b); }
#endif

constexpr float kInf = __builtin_inff();
constexpr int kStackSize = 640;  // 7 entries per level, binary depth ≤ 48 + 32 (bvh.cpp)

inline Triangle laneTriangle(const TriPack& p, int lane) {
  float f[9];
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a) f[k * 3 + a] = p.v[k][a][lane];
  Triangle t;
  std::memcpy(static_cast<void*>(&t), f, sizeof f);
  return t;
}

inline uint32_t floatBits(float x) { return __builtin_bit_cast(uint32_t, x); }
inline float bitsFloat(uint32_t x) { return __builtin_bit_cast(float, x); }
inline int ctz(unsigned m) { return __builtin_ctz(m); }

// The axes that get slab distances: those the ray is not parallel to (a plain struct, not std::array:
// see the top of this file).
struct SlabAxes {
  int axis[3];
};
constexpr SlabAxes slabAxesOf(unsigned parallel) {
  SlabAxes s{};
  for (int a = 0, i = 0; a < 3; ++a)
    if (!(parallel >> a & 1)) s.axis[i++] = a;
  return s;
}

// Where a node's near and far planes lie for each axis (floats into Node::box), per sign pattern of
// the ray's direction (bit a: negative along axis a): a table, so that a ray's set-up only picks a row.
struct SlabOffsets {
  int nearOff[3], farOff[3];
};
constexpr SlabOffsets slabOffsetsOf(unsigned negative) {
  SlabOffsets s{};
  for (int a = 0; a < 3; ++a) {
    const int nearSide = int(negative >> a & 1);
    s.nearOff[a] = (nearSide * 3 + a) * 8;
    s.farOff[a] = ((1 - nearSide) * 3 + a) * 8;
  }
  return s;
}
constexpr SlabOffsets kSlabOffsets[8] = {slabOffsetsOf(0), slabOffsetsOf(1), slabOffsetsOf(2), slabOffsetsOf(3),
                                         slabOffsetsOf(4), slabOffsetsOf(5), slabOffsetsOf(6), slabOffsetsOf(7)};

#define RTR_INLINE inline __attribute__((always_inline))

// Counting (bvh_counted.cpp only): RTR_COUNT(c.nodes += 1) adds to the thread's BvhCounters; elsewhere
// it compiles to nothing.
#if RTR_BVH_COUNT
#define RTR_COUNT(...)                \
  do {                                \
    BvhCounters& c = Bvh::counters(); \
    __VA_ARGS__;                      \
  } while (0)
#else
#define RTR_COUNT(...) \
  do {                 \
  } while (0)
#endif

// The real triangles of a pack (a short pack repeats its last one).
inline unsigned realLanes(const TriPack& pk) {
  unsigned m = 1;
  for (int lane = 1; lane < 8; ++lane) m |= unsigned(pk.prim[lane] != pk.prim[lane - 1]) << lane;
  return m;
}

// Where a walk is: the stack's fill, the node or leaf to visit next, the closest hit so far. The stack
// itself (kStackSize entries) is passed beside it: as a member it kept the compiler from holding these
// in registers (measured slower). An entry: the entry distance's bits above the node reference,
// so one integer compare sorts.
struct Cursor {
  int sp;
  uint32_t ref;
  float tHit;
  bool found;
};

// One ray's walk through the BVH, front to back: the per-ray constants and the steps of the walk.
// run() walks to the end; step() does one node or one leaf, so that two walks can be interleaved on one
// thread (walkPair below). Parallel: bit a set when the ray runs parallel to axis a (a zero direction
// component), see below.
template <bool AnyHit, unsigned Parallel>
struct Walker {
  static_assert(sizeof(Triangle) == 9 * sizeof(float));
  static constexpr int kSlabs = 3 - __builtin_popcount(Parallel);
  static constexpr SlabAxes kSlabAxes = slabAxesOf(Parallel);

  const Bvh::View bvh;  // a copy: through a reference, the node array's address was reloaded after every pop
  const Ray& ray;
  const IntersectMethod method;
  F oAxis[3];
  const SlabOffsets* off;  // a row of kSlabOffsets
#if RTR_BVH_AVX2
  F rNear[3], qNear[3], rFar[3], qFar[3];
#else
  F org[3], rdir[3], rdirFar[3];
#endif
  // The watertight test's constants, made on the ray's first leaf (most rays of a view that miss, or
  // end after a node or two, never reach one: docs/bench/trace.md, round 17).
  mutable bool sheared = false;
  mutable int kx, ky, kz;
  mutable F ox, oy, oz, sx, sy, sz;

  RTR_INLINE Walker(const Bvh::View& view, const Ray& r, IntersectMethod m) : bvh(view), ray(r), method(m) {
    const float o[3] = {ray.origin.x, ray.origin.y, ray.origin.z};
    const float d[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
    // Slab distances, conservative under rounding so that the BVH keeps the watertight test watertight:
    // a box the ray really meets is never culled. A NaN distance (an overflow) never culls either: the
    // test below is "not tNear > tFar". An axis the ray runs parallel to (orthographic views, axis-aligned
    // rays) has no slab distances (they would be infinite or NaN and cull nothing: every box across the
    // view visited); its test is exact instead, lo ≤ o ≤ hi.
    for (int a = 0; a < 3; ++a)
      if (Parallel >> a & 1) oAxis[a] = set1(o[a]);
#if RTR_BVH_AVX2
    // One FMA per slab: t = box·r − o·r. The near distance uses r shrunk by 8 ulps and o·r pushed up by
    // 4 ulps, the far one r grown and o·r pushed down: enough to cover every rounding (of 1/d, of o·r, of
    // the FMA), so a near distance never ends up past the true one, nor a far one short of it.
    // All three axes at once in one SSE register, one division for the three reciprocals (the same
    // operations per lane as one axis alone): the per-ray set-up is a good part of a ray's time
    // (measured with rays that miss the root).
    const __m128 r4 = _mm_div_ps(_mm_set1_ps(1.0f), _mm_setr_ps(d[0], d[1], d[2], 1.0f)),
                 o4 = _mm_setr_ps(o[0], o[1], o[2], 0.0f);
    const __m128 rn4 = _mm_mul_ps(r4, _mm_set1_ps(1.0f - 0x1p-21f)), rf4 = _mm_mul_ps(r4, _mm_set1_ps(1.0f + 0x1p-21f));
    const __m128 qn0 = _mm_mul_ps(o4, rn4), qf0 = _mm_mul_ps(o4, rf4), absMask = _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF));
    const __m128 qn4 =
        _mm_add_ps(qn0, _mm_add_ps(_mm_mul_ps(_mm_and_ps(qn0, absMask), _mm_set1_ps(0x1p-22f)), _mm_set1_ps(0x1p-100f)));
    const __m128 qf4 =
        _mm_sub_ps(qf0, _mm_add_ps(_mm_mul_ps(_mm_and_ps(qf0, absMask), _mm_set1_ps(0x1p-22f)), _mm_set1_ps(0x1p-100f)));
    rNear[0] = lane<0>(rn4);
    rNear[1] = lane<1>(rn4);
    rNear[2] = lane<2>(rn4);
    qNear[0] = lane<0>(qn4);
    qNear[1] = lane<1>(qn4);
    qNear[2] = lane<2>(qn4);
    rFar[0] = lane<0>(rf4);
    rFar[1] = lane<1>(rf4);
    rFar[2] = lane<2>(rf4);
    qFar[0] = lane<0>(qf4);
    qFar[1] = lane<1>(qf4);
    qFar[2] = lane<2>(qf4);
    off = &kSlabOffsets[unsigned(_mm_movemask_ps(_mm_cmplt_ps(r4, _mm_setzero_ps()))) & 7u];
#else
    // (box − o)·r, the far one scaled by 1 + 2·gamma(4) (Ize 2013; the scale folded into r, one more rounding).
    constexpr float kFarScale = 1.0f + 2.0f * (4.0f * 0x1p-24f) / (1.0f - 4.0f * 0x1p-24f);
    unsigned negative = 0;
    for (int a = 0; a < 3; ++a) {
      const float inv = 1.0f / d[a];
      org[a] = set1(o[a]);
      rdir[a] = set1(inv);
      rdirFar[a] = set1(inv * kFarScale);
      negative |= unsigned(inv < 0.0f) << a;
    }
    off = &kSlabOffsets[negative];
#endif
  }

#if RTR_BVH_AVX2
  // The same walk for lane i of a packet (PacketWalker), whose constructor made these slab constants
  // with the operations above, eight rays at a time: a lone ray's set-up without its slab arithmetic
  // (a shadow packet on the sphere hands ten rays a packet to lone walks).
  RTR_INLINE Walker(const Bvh::View& view, const Ray& r, IntersectMethod m, int i, const F* o3, const F* rn, const F* qn,
                    const F* rf, const F* qf, const F* negative)
      : bvh(view), ray(r), method(m) {
    const __m256i idx = _mm256_set1_epi32(i);
    auto laneOf = [&](F v) { return F{_mm256_permutevar8x32_ps(v.v, idx)}; };
    unsigned signs = 0;
    for (int a = 0; a < 3; ++a) {
      oAxis[a] = laneOf(o3[a]);
      rNear[a] = laneOf(rn[a]);
      qNear[a] = laneOf(qn[a]);
      rFar[a] = laneOf(rf[a]);
      qFar[a] = laneOf(qf[a]);
      signs |= (bits(negative[a]) >> i & 1) << a;
    }
    off = &kSlabOffsets[signs];
    initShear();
  }
#endif

  // The watertight test's shear, constant per ray; vertex axes are loaded in its permuted order.
  // The same operations as WatertightRay's constructor (the scalar test of edge cases builds one and
  // must shear identically), inline here.
  RTR_INLINE void initShear() const {
    const float o[3] = {ray.origin.x, ray.origin.y, ray.origin.z};
    const float d[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
    shearAxes(d, 1, kx, ky, kz);
    const float szs = 1.0f / d[kz];
    ox = set1(o[kx]);
    oy = set1(o[ky]);
    oz = set1(o[kz]);
    sx = set1(d[kx] * szs);
    sy = set1(d[ky] * szs);
    sz = set1(szs);
    sheared = true;
  }
  // The watertight test's axis order for direction d[0], d[stride], d[2 * stride] (packets keep theirs
  // by axis): kz the largest component, kx and ky swapped where it is negative.
  RTR_INLINE static void shearAxes(const float* d, int stride, int& kx, int& ky, int& kz) {
    const float ad[3] = {__builtin_fabsf(d[0]), __builtin_fabsf(d[stride]), __builtin_fabsf(d[2 * stride])};
    kz = ad[0] > ad[1] ? (ad[0] > ad[2] ? 0 : 2) : (ad[1] > ad[2] ? 1 : 2);
    kx = kz == 2 ? 0 : kz + 1;
    ky = kx == 2 ? 0 : kx + 1;
    if (d[kz * stride] < 0.0f) {
      const int t = kx;
      kx = ky;
      ky = t;
    }
  }

  // Tests the inner node at.ref's children: false when it meets none; else at.ref is the child to visit
  // next and the others are on the stack.
  RTR_INLINE bool visitNode(uint64_t* stack, Cursor& at, F tHitV) const {
    RTR_COUNT(c.nodes += 1);
    const Node& n = bvh.nodes[at.ref];
    const float* b = &n.box[0][0][0];
    const F zero = set1(0.0f);
    F tn[3], tf[3];
    for (int i = 0; i < kSlabs; ++i) {
      const int a = kSlabAxes.axis[i];
#if RTR_BVH_AVX2
      tn[i] = fmsub(load(b + off->nearOff[a]), rNear[a], qNear[a]);
      tf[i] = fmsub(load(b + off->farOff[a]), rFar[a], qFar[a]);
#else
      tn[i] = (load(b + off->nearOff[a]) - org[a]) * rdir[a];
      tf[i] = (load(b + off->farOff[a]) - org[a]) * rdirFar[a];
#endif
    }
    // At most two levels of min/max, not a chain: this is the loop's critical path. As floats, a NaN
    // operand drops out or reaches the compare, which visits. As integers (slabMax): with +0 among the
    // near distances a negative one (sign bit set: a negative integer) never wins, and non-negative
    // floats order as their bits do, so tNear is exact; a far distance below zero makes tFar negative
    // (maybe not the most negative, but the box is culled either way), else tFar is exact; a positive
    // NaN wins a max and the compare visits, a negative one drops out of a max or makes tFar NaN.
    F tNear = zero, tFar = tHitV;
    if constexpr (kSlabs == 3) {
      tNear = slabMax(slabMax(tn[0], tn[1]), slabMax(tn[2], zero));
      tFar = slabMin(slabMin(tf[0], tf[1]), slabMin(tf[2], tHitV));
    } else if constexpr (kSlabs == 2) {
      tNear = slabMax(slabMax(tn[0], tn[1]), zero);
      tFar = slabMin(slabMin(tf[0], tf[1]), tHitV);
    } else if constexpr (kSlabs == 1) {
      tNear = slabMax(tn[0], zero);
      tFar = slabMin(tf[0], tHitV);
    }
    F hitBox = ngt(tNear, tFar);
    for (int a = 0; a < 3; ++a)
      if (Parallel >> a & 1) hitBox = hitBox & le(load(n.box[0][a]), oAxis[a]) & ge(load(n.box[1][a]), oAxis[a]);
    unsigned mask = bits(hitBox);
    if (mask == 0) return false;
    const int c0 = ctz(mask);
    mask &= mask - 1;
    if (mask == 0) {
      at.ref = n.child[c0];
      return true;
    }
    // Two or more children: the one visited next is the smallest key, the others go on the stack.
    // Closest hit goes nearest first, so that a hit culls the rest. Any hit goes farthest first: a
    // shadow ray leaves a surface, and the boxes around its origin hold that surface and its
    // neighbours, which rarely block it (measured: docs/bench/trace.md).
    alignas(32) float dist[8];
    store(dist, tNear);
    auto key = [&](int c) {
      const uint32_t d32 = floatBits(dist[c]);
      return uint64_t(AnyHit ? ~d32 : d32) << 32 | n.child[c];
    };
    const int c1 = ctz(mask);
    mask &= mask - 1;
    if (mask == 0) {  // two, the common case
      const uint64_t k0 = key(c0), k1 = key(c1);
      stack[at.sp++] = k0 < k1 ? k1 : k0;
      at.ref = uint32_t(k0 < k1 ? k0 : k1);
      return true;
    }
    // Three or more: insertion sort onto the stack, smallest key on top.
    uint64_t* run = stack + at.sp;
    int k = 0;
    for (mask |= 1u << c0 | 1u << c1; mask; mask &= mask - 1) {
      const uint64_t kc = key(ctz(mask));
      int j = k++;
      while (j > 0 && run[j - 1] < kc) {
        run[j] = run[j - 1];
        --j;
      }
      run[j] = kc;
    }
    at.sp += k - 1;
    at.ref = uint32_t(run[k - 1]);
    return true;
  }

  // Tests the leaf at.ref's triangles, keeping the closest in at.tHit and hit; true when an any-hit query
  // has found its hit (the walk is over).
  RTR_INLINE bool testLeaf(Cursor& at, Hit& hit, F tHitV) const {
    const F zero = set1(0.0f), signBit = set1(-0.0f);
    const uint32_t first = at.ref & 0x0FFFFFFFu, np = ((at.ref >> 28) & 7u) + 1;
    RTR_COUNT(c.leaves += 1);
    if (!sheared) initShear();
    for (uint32_t p = first; p < first + np; ++p) {
      const TriPack& pk = bvh.packs[p];
      RTR_COUNT(c.packs += 1; c.triangles += unsigned(__builtin_popcount(realLanes(pk))));
      if (method != IntersectMethod::Watertight) {
        for (int lane = 0; lane < 8; ++lane) {
          const uint32_t prim = pk.prim[lane];
          if (AnyHit && (prim & Bvh::kNoShadowBit)) continue;
          Ray r = ray;
          r.tMax = at.tHit;
          float b1, b2;
          const float t = intersect(method, r, laneTriangle(pk, lane), b1, b2);
          if (t > 0.0f) {
            if constexpr (AnyHit) return true;
            at.tHit = t;
            hit = {t, b1, b2, prim & ~Bvh::kNoShadowBit};
            at.found = true;
          }
        }
        continue;
      }
      // The 8-wide watertight test: the same float operations in the same order as the scalar one
      // (no FMA), so both agree bit for bit.
      const F Az = load(pk.v[0][kz]) - oz, Bz = load(pk.v[1][kz]) - oz, Cz = load(pk.v[2][kz]) - oz;
      const F ax = (load(pk.v[0][kx]) - ox) - sx * Az, ay = (load(pk.v[0][ky]) - oy) - sy * Az;
      const F bx = (load(pk.v[1][kx]) - ox) - sx * Bz, by = (load(pk.v[1][ky]) - oy) - sy * Bz;
      const F cx = (load(pk.v[2][kx]) - ox) - sx * Cz, cy = (load(pk.v[2][ky]) - oy) - sy * Cz;
      const F U = cx * by - cy * bx, V = ax * cy - ay * cx, W = bx * ay - by * ax;
      // Inside: U, V, W of one sign. Lanes with a zero go to the edge path; a NaN lane that passes
      // here fails the t test below (as in the scalar routine, where it fails here). So det, a sum of
      // nonzero terms of one sign, is never zero on these lanes: no test for it.
      // Exactly on an edge in float: the scalar routine decides in double.
      unsigned edge = bits(eq(U, zero) | eq(V, zero) | eq(W, zero));
      unsigned m = ~bits((U ^ V) | (V ^ W)) & 0xFFu & ~edge;
      if ((m | edge) == 0) continue;
      const F det = U + V + W;
      const F T = U * (sz * Az) + V * (sz * Bz) + W * (sz * Cz);
      const F detSign = det & signBit;
      const F Ts = T ^ detSign;
      m &= bits(gt(Ts, zero) & lt(Ts, tHitV * (det ^ detSign)));
      if constexpr (AnyHit) {
        const unsigned casters = ~topBits(pk.prim);
        if (m & casters) return true;
        edge &= casters;
      } else if (m) {
        const F inv = set1(1.0f) / det;
        alignas(32) float tv[8], iv[8], vv[8], wv[8];
        store(tv, T * inv);
        store(iv, inv);
        store(vv, V);
        store(wv, W);
        for (; m; m &= m - 1) {
          const int lane = ctz(m);
          const float t = tv[lane];
          if (t > 0.0f && t < at.tHit) {
            at.tHit = t;
            hit = {t, vv[lane] * iv[lane], wv[lane] * iv[lane], pk.prim[lane] & ~Bvh::kNoShadowBit};
            at.found = true;
          }
        }
      }
      for (; edge; edge &= edge - 1) {
        const int lane = ctz(edge);
        WatertightRay r(ray);
        r.tMax = at.tHit;
        float b1, b2;
        const float t = intersectWatertight(r, laneTriangle(pk, lane), b1, b2);
        if (t > 0.0f) {
          if constexpr (AnyHit) return true;
          at.tHit = t;
          hit = {t, b1, b2, pk.prim[lane] & ~Bvh::kNoShadowBit};
          at.found = true;
        }
      }
    }
    return false;
  }

  // Takes the next entry off the stack into at.ref, skipping those beyond the closest hit; false when
  // none is left.
  RTR_INLINE static bool pop(const uint64_t* stack, Cursor& at) {
    while (at.sp > 0) {
      const uint64_t e = stack[--at.sp];
      if (!AnyHit && bitsFloat(uint32_t(e >> 32)) > at.tHit) continue;
      at.ref = uint32_t(e);
      return true;
    }
    return false;
  }

  // Walks on from at.ref to the end; returns whether the ray hit.
  RTR_INLINE bool run(uint64_t* stack, Cursor& at, Hit& hit) const {
    for (;;) {
      const F tHitV = set1(at.tHit);
      while (!(at.ref & Bvh::kLeafBit))
        if (!visitNode(stack, at, tHitV)) goto next;
      if (AnyHit && testLeaf(at, hit, tHitV)) return at.found = true;
      if (!AnyHit) testLeaf(at, hit, tHitV);
    next:
      if (!pop(stack, at)) return at.found;
    }
  }

  // One node or one leaf; false when the walk is over (the result is in at.found).
  RTR_INLINE bool step(uint64_t* stack, Cursor& at, Hit& hit) const {
    const F tHitV = set1(at.tHit);
    if (!(at.ref & Bvh::kLeafBit)) {
      if (visitNode(stack, at, tHitV)) return true;
    } else if (testLeaf(at, hit, tHitV)) {
      at.found = true;
      return false;
    }
    return pop(stack, at);
  }
};

#include "trace/bvh_packet.inl"

}  // namespace

// The axes a ray runs parallel to (zero direction components) as bits; 7 (no direction) meets nothing.
inline unsigned parallelAxes(const Ray& r) {
  const glm::vec3& d = r.direction;
  return unsigned(d.x == 0.0f) | unsigned(d.y == 0.0f) << 1 | unsigned(d.z == 0.0f) << 2;
}

template <bool AnyHit, unsigned Parallel>
bool walk(const Bvh::View& bvh, const Ray& ray, IntersectMethod method, Hit& hit) {
  uint64_t stack[kStackSize];
  Cursor at{0, bvh.root, ray.tMax, false};
  return Walker<AnyHit, Parallel>(bvh, ray, method).run(stack, at, hit);
}

// Two rays, one node or leaf of each in turn: while one waits for memory or recovers from a mispredicted
// branch, the other's independent work fills the core (docs/bench/trace.md, round 5). Each gets exactly
// the result it gets alone.
template <bool AnyHit, unsigned Parallel>
unsigned walkPair(const Bvh::View& bvh, const Ray* rays, IntersectMethod method, Hit* hits) {
  uint64_t stackA[kStackSize], stackB[kStackSize];
  const Walker<AnyHit, Parallel> a(bvh, rays[0], method), b(bvh, rays[1], method);
  Cursor atA{0, bvh.root, rays[0].tMax, false}, atB{0, bvh.root, rays[1].tMax, false};
  bool moreA = true, moreB = true;
  while (moreA && moreB) {
    moreA = a.step(stackA, atA, hits[0]);
    moreB = b.step(stackB, atB, hits[1]);
  }
  if (moreA) a.run(stackA, atA, hits[0]);
  if (moreB) b.run(stackB, atB, hits[1]);
  return unsigned(atA.found) | unsigned(atB.found) << 1;
}

// One traversal per set of axes the ray runs parallel to.
template <bool AnyHit>
bool dispatch(const Bvh::View& bvh, const Ray& ray, IntersectMethod method, Hit& hit) {
  switch (parallelAxes(ray)) {
    case 0: return walk<AnyHit, 0>(bvh, ray, method, hit);
    case 1: return walk<AnyHit, 1>(bvh, ray, method, hit);
    case 2: return walk<AnyHit, 2>(bvh, ray, method, hit);
    case 3: return walk<AnyHit, 3>(bvh, ray, method, hit);
    case 4: return walk<AnyHit, 4>(bvh, ray, method, hit);
    case 5: return walk<AnyHit, 5>(bvh, ray, method, hit);
    case 6: return walk<AnyHit, 6>(bvh, ray, method, hit);
    default: return false;
  }
}

// Pairs whose rays run parallel to the same axes (all of a view's rays, orthographic or not) walk
// together; others one at a time.
template <bool AnyHit>
unsigned dispatchPair(const Bvh::View& bvh, const Ray* rays, IntersectMethod method, Hit* hits) {
  const unsigned p = parallelAxes(rays[0]);
  switch (p == parallelAxes(rays[1]) ? p : 8u) {
    case 0: return walkPair<AnyHit, 0>(bvh, rays, method, hits);
    case 1: return walkPair<AnyHit, 1>(bvh, rays, method, hits);
    case 2: return walkPair<AnyHit, 2>(bvh, rays, method, hits);
    case 3: return walkPair<AnyHit, 3>(bvh, rays, method, hits);
    case 4: return walkPair<AnyHit, 4>(bvh, rays, method, hits);
    case 5: return walkPair<AnyHit, 5>(bvh, rays, method, hits);
    case 6: return walkPair<AnyHit, 6>(bvh, rays, method, hits);
    case 7: return 0;
    default:
      return unsigned(dispatch<AnyHit>(bvh, rays[0], method, hits[0])) | unsigned(dispatch<AnyHit>(bvh, rays[1], method, hits[1]))
                                                                             << 1;
  }
}

// Packets whose rays all run parallel to the same axes (all of a view's rays, orthographic or not) and
// use the watertight test; others go ray by ray. Closest hit: returns the rays the caller must trace
// again alone (ties, see bvh_packet.inl). Any hit: returns the occluded rays.
template <bool AnyHit>
unsigned dispatchPacket(const Bvh::View& bvh, const Ray* rays, int n, IntersectMethod method, Hit* hits, int leafRays,
                        int aloneRays) {
  bool same = method == IntersectMethod::Watertight && n > 1;
  const PacketRays pr = gatherRays(rays, n);
  unsigned p = 0;  // the axes every ray runs parallel to; same: no ray is parallel to another
  for (int a = 0; a < 3; ++a) {
    const unsigned zero = bits(eq(pr.d[a], set1(0.0f)));
    if (zero == 0xFFu) p |= 1u << a;
    else if (zero) same = false;
  }
  switch (same ? p : 8u) {
    case 0: return walkPacket<AnyHit, 0>(bvh, rays, n, pr, method, hits, leafRays, aloneRays);
    case 1: return walkPacket<AnyHit, 1>(bvh, rays, n, pr, method, hits, leafRays, aloneRays);
    case 2: return walkPacket<AnyHit, 2>(bvh, rays, n, pr, method, hits, leafRays, aloneRays);
    case 3: return walkPacket<AnyHit, 3>(bvh, rays, n, pr, method, hits, leafRays, aloneRays);
    case 4: return walkPacket<AnyHit, 4>(bvh, rays, n, pr, method, hits, leafRays, aloneRays);
    case 5: return walkPacket<AnyHit, 5>(bvh, rays, n, pr, method, hits, leafRays, aloneRays);
    case 6: return walkPacket<AnyHit, 6>(bvh, rays, n, pr, method, hits, leafRays, aloneRays);
    case 7: return 0;
    default: {
      unsigned m = 0;
      for (int i = 0; i < n; ++i) m |= unsigned(dispatch<AnyHit>(bvh, rays[i], method, hits[i])) << i;
      return AnyHit ? m : 0;
    }
  }
}

bool closest(const Bvh::View& bvh, const Ray& ray, IntersectMethod method, Hit& hit) {
  return dispatch<false>(bvh, ray, method, hit);
}
bool occluded(const Bvh::View& bvh, const Ray& ray, IntersectMethod method, Hit& scratch) {
  return dispatch<true>(bvh, ray, method, scratch);
}
unsigned closestPair(const Bvh::View& bvh, const Ray* rays, IntersectMethod method, Hit* hits) {
  return dispatchPair<false>(bvh, rays, method, hits);
}
unsigned occludedPair(const Bvh::View& bvh, const Ray* rays, IntersectMethod method, Hit* scratch) {
  return dispatchPair<true>(bvh, rays, method, scratch);
}
unsigned closestPacket(const Bvh::View& bvh, const Ray* rays, int n, IntersectMethod method, Hit* hits, int leafRays,
                       int aloneRays) {
  return dispatchPacket<false>(bvh, rays, n, method, hits, leafRays, aloneRays);
}
unsigned occludedPacket(const Bvh::View& bvh, const Ray* rays, int n, IntersectMethod method, Hit* scratch, int leafRays,
                        int aloneRays) {
  return dispatchPacket<true>(bvh, rays, n, method, scratch, leafRays, aloneRays);
}

}  // namespace rtr::trace::RTR_BVH_ISA

#undef RTR_INLINE
#undef RTR_COUNT
