// BVH traversal, compiled once per instruction set: bvh_sse.cpp and bvh_avx2.cpp include this with
// RTR_BVH_ISA naming the namespace (sse, avx2) and RTR_BVH_AVX2 set for the 8-wide registers.
// Everything here is inline and inside that namespace, and uses no glm or std function templates: an
// out-of-line copy compiled for AVX2 must never be what the SSE build links to.
#include <immintrin.h>

#include <cstring>

#include "trace/bvh.hpp"

namespace rtr::trace::RTR_BVH_ISA {
namespace {

// Eight floats: one AVX register, or two SSE ones with the same per-lane results.
#if RTR_BVH_AVX2
struct F { __m256 v; };
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
inline unsigned bits(F a) { return unsigned(_mm256_movemask_ps(a.v)); }
inline void store(float* p, F a) { _mm256_store_ps(p, a.v); }
// The top bits of eight 32-bit integers.
inline unsigned topBits(const uint32_t* p) {
  return unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_load_si256(reinterpret_cast<const __m256i*>(p)))));
}
#else
struct F { __m128 a, b; };
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
inline unsigned bits(F x) { return unsigned(_mm_movemask_ps(x.a)) | unsigned(_mm_movemask_ps(x.b)) << 4; }
inline void store(float* p, F x) { _mm_store_ps(p, x.a); _mm_store_ps(p + 4, x.b); }
inline unsigned topBits(const uint32_t* p) {
  const __m128i* q = reinterpret_cast<const __m128i*>(p);
  return unsigned(_mm_movemask_ps(_mm_castsi128_ps(_mm_load_si128(q)))) |
         unsigned(_mm_movemask_ps(_mm_castsi128_ps(_mm_load_si128(q + 1)))) << 4;
}
#endif

// 1 + 2·gamma(4): the far slab distance scaled by it (the scale folded into the reciprocal, one more
// rounding) stays at or beyond every rounded near distance of a box the ray really meets (Ize 2013), so
// the BVH keeps the watertight triangle test watertight.
constexpr float kFarScale = 1.0f + 2.0f * (4.0f * 0x1p-24f) / (1.0f - 4.0f * 0x1p-24f);
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

template <bool AnyHit>
bool traverse(const Bvh::View& bvh, const Ray& ray, IntersectMethod method, Hit& hit) {
  static_assert(sizeof(Triangle) == 9 * sizeof(float));
  const WatertightRay wr(ray);
  const float o[3] = {ray.origin.x, ray.origin.y, ray.origin.z};
  const float d[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
  F org[3], rdir[3], rdirFar[3];
  int nearOff[3], farOff[3];
  for (int a = 0; a < 3; ++a) {
    // A zero component gives an infinite reciprocal and, on the slab's plane, 0·inf = NaN: the min/max
    // below are ordered so that a NaN slab distance is ignored.
    const float inv = 1.0f / d[a];
    org[a] = set1(o[a]);
    rdir[a] = set1(inv);
    rdirFar[a] = set1(inv * kFarScale);
    const int nearSide = inv < 0.0f ? 1 : 0;
    nearOff[a] = (nearSide * 3 + a) * 8;
    farOff[a] = ((1 - nearSide) * 3 + a) * 8;
  }
  // The watertight test's shear, constant per ray; vertex axes are loaded in its permuted order.
  const int kx = wr.kx, ky = wr.ky, kz = wr.kz;
  const F ox = set1(o[kx]), oy = set1(o[ky]), oz = set1(o[kz]);
  const F sx = set1(wr.sx), sy = set1(wr.sy), sz = set1(wr.sz);
  const F zero = set1(0.0f), signBit = set1(-0.0f);

  // Stack entries: the entry distance's bits above the node reference, so one integer compare sorts.
  uint64_t stack[kStackSize];
  int sp = 0;
  uint32_t ref = bvh.root;
  float tHit = ray.tMax;
  bool found = false;

  for (;;) {
    const F tHitV = set1(tHit);
    while (!(ref & Bvh::kLeafBit)) {
      const Node& n = bvh.nodes[ref];
      const float* b = &n.box[0][0][0];
      const F tx0 = (load(b + nearOff[0]) - org[0]) * rdir[0];
      const F ty0 = (load(b + nearOff[1]) - org[1]) * rdir[1];
      const F tz0 = (load(b + nearOff[2]) - org[2]) * rdir[2];
      const F tx1 = (load(b + farOff[0]) - org[0]) * rdirFar[0];
      const F ty1 = (load(b + farOff[1]) - org[1]) * rdirFar[1];
      const F tz1 = (load(b + farOff[2]) - org[2]) * rdirFar[2];
      const F tNear = vmax(tz0, vmax(ty0, vmax(tx0, zero)));
      const F tFar = vmin(tz1, vmin(ty1, vmin(tx1, tHitV)));
      unsigned mask = bits(le(tNear, tFar));
      if (mask == 0) goto pop;
      if constexpr (AnyHit) {
        ref = n.child[ctz(mask)];
        for (mask &= mask - 1; mask; mask &= mask - 1) stack[sp++] = n.child[ctz(mask)];
        continue;
      } else {
        const int c0 = ctz(mask);
        mask &= mask - 1;
        if (mask == 0) { ref = n.child[c0]; continue; }
        alignas(32) float dist[8];
        store(dist, tNear);
        // Two or more: push them sorted, nearest on top, then take the top.
        uint64_t* run = stack + sp;
        int k = 0;
        for (mask |= 1u << c0; mask; mask &= mask - 1) {
          const int c = ctz(mask);
          const uint64_t key = uint64_t(floatBits(dist[c])) << 32 | n.child[c];
          int j = k++;
          while (j > 0 && run[j - 1] < key) { run[j] = run[j - 1]; --j; }
          run[j] = key;
        }
        sp += k - 1;
        ref = uint32_t(run[k - 1]);
        continue;
      }
    }
    {
      const uint32_t first = ref & 0x0FFFFFFFu, np = ((ref >> 28) & 7u) + 1;
      for (uint32_t p = first; p < first + np; ++p) {
        const TriPack& pk = bvh.packs[p];
        if (method != IntersectMethod::Watertight) {
          for (int lane = 0; lane < 8; ++lane) {
            const uint32_t prim = pk.prim[lane];
            if (AnyHit && (prim & Bvh::kNoShadowBit)) continue;
            Ray r = ray;
            r.tMax = tHit;
            float b1, b2;
            const float t = intersect(method, r, laneTriangle(pk, lane), b1, b2);
            if (t > 0.0f) {
              if constexpr (AnyHit) return true;
              tHit = t; hit = {t, b1, b2, prim & ~Bvh::kNoShadowBit}; found = true;
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
        const F inside = (ge(U, zero) & ge(V, zero) & ge(W, zero)) | (le(U, zero) & le(V, zero) & le(W, zero));
        // Exactly on an edge in float: the scalar routine decides in double.
        unsigned edge = bits(eq(U, zero) | eq(V, zero) | eq(W, zero));
        unsigned m = bits(inside) & ~edge;
        if ((m | edge) == 0) continue;
        const F det = U + V + W;
        const F T = U * (sz * Az) + V * (sz * Bz) + W * (sz * Cz);
        const F detSign = det & signBit;
        const F Ts = T ^ detSign;
        m &= bits(neq(det, zero) & gt(Ts, zero) & lt(Ts, tHitV * (det ^ detSign)));
        if constexpr (AnyHit) {
          const unsigned casters = ~topBits(pk.prim);
          if (m & casters) return true;
          edge &= casters;
        } else if (m) {
          const F inv = set1(1.0f) / det;
          alignas(32) float tv[8], iv[8], vv[8], wv[8];
          store(tv, T * inv); store(iv, inv); store(vv, V); store(wv, W);
          for (; m; m &= m - 1) {
            const int lane = ctz(m);
            const float t = tv[lane];
            if (t > 0.0f && t < tHit) {
              tHit = t;
              hit = {t, vv[lane] * iv[lane], wv[lane] * iv[lane], pk.prim[lane] & ~Bvh::kNoShadowBit};
              found = true;
            }
          }
        }
        for (; edge; edge &= edge - 1) {
          const int lane = ctz(edge);
          WatertightRay r = wr;
          r.tMax = tHit;
          float b1, b2;
          const float t = intersectWatertight(r, laneTriangle(pk, lane), b1, b2);
          if (t > 0.0f) {
            if constexpr (AnyHit) return true;
            tHit = t; hit = {t, b1, b2, pk.prim[lane] & ~Bvh::kNoShadowBit}; found = true;
          }
        }
      }
    }
  pop:
    for (;;) {
      if (sp == 0) return found;
      const uint64_t e = stack[--sp];
      if (!AnyHit && bitsFloat(uint32_t(e >> 32)) > tHit) continue;
      ref = uint32_t(e);
      break;
    }
  }
}

}  // namespace

bool closest(const Bvh::View& bvh, const Ray& ray, IntersectMethod method, Hit& hit) {
  return traverse<false>(bvh, ray, method, hit);
}
bool occluded(const Bvh::View& bvh, const Ray& ray, IntersectMethod method, Hit& scratch) {
  return traverse<true>(bvh, ray, method, scratch);
}

}  // namespace rtr::trace::RTR_BVH_ISA
