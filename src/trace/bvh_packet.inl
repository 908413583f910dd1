// Packets of up to eight rays through the BVH (included by bvh_traverse.inl, inside its namespace; the
// same rules: inline, no glm or std function templates). Lanes are rays here: a node's children are
// tested one after another against all rays of the packet at once, each ray with exactly the slab
// arithmetic of its single-ray walk. Leaves are tested all rays at once (lanes = rays) where enough rays
// reach them, else ray by ray with the single-ray 8-wide triangle test. Four rays or fewer left in a
// subtree walk it as single rays, two at a time. See docs/tracer.md.
//
// Why the results equal the single-ray ones bit for bit:
// * Any hit: a ray's tMax never changes, so each box and each triangle gets the same answer for a ray
//   whatever the order; the packet visits for each ray exactly the boxes its single walk may visit.
// * Closest hit: every triangle the ray meets with t in (0, tMax) (the single-ray test's own predicate,
//   t computed by the same operations) is a candidate; boxes are culled only beyond the best candidate
//   by a window of 2⁻⁹ relative. The best candidate is the single walk's answer unless another
//   candidate lies within 2⁻¹⁰ of it (a tie, or a near-tie that traversal order or the test's rounding
//   could decide either way): such rays are reported back and traced again as single rays.

#define RTR_INLINE inline __attribute__((always_inline))

#if RTR_BVH_AVX2
inline F sel(F mask, F a, F b) { return {_mm256_blendv_ps(b.v, a.v, mask.v)}; }  // mask ? a : b
// The min and max over the eight lanes, in every lane (no round trip through a scalar).
inline F allMin(F a) {
  const __m256 m = _mm256_min_ps(a.v, _mm256_permute2f128_ps(a.v, a.v, 1));
  const __m256 m2 = _mm256_min_ps(m, _mm256_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
  return {_mm256_min_ps(m2, _mm256_shuffle_ps(m2, m2, _MM_SHUFFLE(2, 3, 0, 1)))};
}
inline F allMax(F a) {
  const __m256 m = _mm256_max_ps(a.v, _mm256_permute2f128_ps(a.v, a.v, 1));
  const __m256 m2 = _mm256_max_ps(m, _mm256_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
  return {_mm256_max_ps(m2, _mm256_shuffle_ps(m2, m2, _MM_SHUFFLE(2, 3, 0, 1)))};
}
inline float minLane(F a) { return _mm256_cvtss_f32(allMin(a).v); }
// Lane i all ones where bit i of m is set.
inline F laneMask(unsigned m) {
  const __m256i b = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  return {_mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(int(m)), b), b))};
}
#else
inline F sel(F mask, F x, F y) { return {_mm_blendv_ps(y.a, x.a, mask.a), _mm_blendv_ps(y.b, x.b, mask.b)}; }
inline float minLane(F x) {
  const __m128 m = _mm_min_ps(x.a, x.b);
  const __m128 m2 = _mm_min_ps(m, _mm_movehl_ps(m, m));
  return _mm_cvtss_f32(_mm_min_ss(m2, _mm_shuffle_ps(m2, m2, 1)));
}
inline F laneMask(unsigned m) {
  const __m128i v = _mm_set1_epi32(int(m)), lo = _mm_setr_epi32(1, 2, 4, 8), hi = _mm_setr_epi32(16, 32, 64, 128);
  return {_mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(v, lo), lo)),
          _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(v, hi), hi))};
}
#endif

// A packet's rays with lanes = rays (lanes n to 7 repeat ray 0), read once into vectors by scalar loads:
// eight scalar stores read back as one vector stall on store forwarding, and a gather was slower still
// (AMD VM); most temple packets end after a node or two, so their set-up is a good part of their time
// (docs/bench/trace.md, round 9).
struct PacketRays {
  F o[3], d[3], tMax;
};
RTR_INLINE F lanesOf(const float* const* p, int k) {  // p[i][k] in lane i
#if RTR_BVH_AVX2
  return {_mm256_setr_ps(p[0][k], p[1][k], p[2][k], p[3][k], p[4][k], p[5][k], p[6][k], p[7][k])};
#else
  return {_mm_setr_ps(p[0][k], p[1][k], p[2][k], p[3][k]), _mm_setr_ps(p[4][k], p[5][k], p[6][k], p[7][k])};
#endif
}
RTR_INLINE PacketRays gatherRays(const Ray* r, int n) {
  const float* p[8];
  for (int i = 0; i < 8; ++i) p[i] = &r[i < n ? i : 0].origin.x;  // origin, direction, tMax: seven floats
  static_assert(sizeof(Ray) == 7 * sizeof(float));
  return {{lanesOf(p, 0), lanesOf(p, 1), lanesOf(p, 2)}, {lanesOf(p, 3), lanesOf(p, 4), lanesOf(p, 5)}, lanesOf(p, 6)};
}

constexpr float kTieWindow = 0x1p-10f;
struct PacketEntry {
  F tNear;  // per ray; a ray whose entry is beyond its cull distance when popped drops out
  uint32_t ref, mask;
};

template <bool AnyHit, unsigned Parallel>
struct PacketWalker {
  using W = Walker<AnyHit, Parallel>;
  static constexpr int kSlabs = W::kSlabs;
  static constexpr SlabAxes kSlabAxes = W::kSlabAxes;

  const Bvh::View bvh;
  const Ray* rays;
  Hit* hits;
  F oAxis[3], neg[3];
#if RTR_BVH_AVX2
  F rNear[3], qNear[3], rFar[3], qFar[3];
#else
  F org[3], rdir[3], rdirFar[3];
#endif
  alignas(32) float tMax[8], cull[8], best[8], second[8];
  // The watertight test's per-ray constants with lanes = rays, for leaves tested all rays at once; valid
  // when every ray has the same axis order kx, ky, kz (sameShear). Made on the first such leaf (shear()).
  F shO[3], shS[3];
  int kx = 0, ky = 0, kz = 0;
  bool sameShear = true, sheared = false;
  const int nRays, leafRays, aloneRays;  // Bvh::kPacketLeafRays, kPacketAloneRays
#if RTR_BVH_AVX2
  // The packet's interval: per axis, bounds over its rays of the slab constants, for one conservative
  // test of a node's eight children at once (lanes = children) before each child is tested against the
  // rays (lanes = rays). Without it a node visit costs one 8-wide pass per child, as many passes a ray as
  // single rays take (counted: docs/bench/trace.md, round 8). Only when every ray has the same sign on
  // each axis and finite, non-zero constants, and finite origins on the axes the rays run parallel to
  // (then no bound is NaN).
  F rnLo[3], rnHi[3], qnHi[3], rfLo[3], rfHi[3], qfLo[3], oLo[3], oHi[3];  // o: on parallel axes
  int nearOff[3], farOff[3];
  bool interval = false;
#endif
  alignas(W) unsigned char walkers[8][sizeof(W)];  // each ray's single-ray walk, for leaves and lone rays

  IntersectMethod method;
  unsigned built = 0;  // the walkers constructed so far: only rays that need one pay its set-up
  // (on the temple most packets miss after a node or two, and eight set-ups cost more than the walk)
  RTR_INLINE const W& walker(int i) {
    if (!(built >> i & 1)) {
#if RTR_BVH_AVX2
      new (walkers[i]) W(bvh, rays[i], method, i, oAxis, rNear, qNear, rFar, qFar, neg);
#else
      new (walkers[i]) W(bvh, rays[i], method);
      reinterpret_cast<const W*>(walkers[i])->initShear();  // leafCandidates reads its shear
#endif
      built |= 1u << i;
    }
    return *reinterpret_cast<const W*>(walkers[i]);
  }

  RTR_INLINE PacketWalker(const Bvh::View& view, const Ray* r, int n, const PacketRays& pr, Hit* h, IntersectMethod m,
                          int minLeafRays, int maxAloneRays)
      : bvh(view), rays(r), hits(h), nRays(n), leafRays(minLeafRays), aloneRays(maxAloneRays), method(m) {
    store(tMax, pr.tMax);
    store(cull, pr.tMax);
    store(best, set1(kInf));
    store(second, set1(kInf));
    // Per ray, the operations of Walker's constructor (there done three axes at a time, here eight
    // rays at a time: the same per-lane results), so the boxes are culled exactly as for a single ray.
    const F zero = set1(0.0f);
#if RTR_BVH_AVX2
    const F absMask = set1(bitsFloat(0x7FFFFFFFu));
#endif
#if RTR_BVH_AVX2
    F rcpLo[3], rcpHi[3];
#endif
    for (int a = 0; a < 3; ++a) {
      oAxis[a] = pr.o[a];
      const F rcp = set1(1.0f) / pr.d[a];
#if RTR_BVH_AVX2
      if (!(Parallel >> a & 1)) {
        rcpLo[a] = allMin(rcp);
        rcpHi[a] = allMax(rcp);
      }
#endif
      neg[a] = lt(rcp, zero);
#if RTR_BVH_AVX2
      rNear[a] = rcp * set1(1.0f - 0x1p-21f);
      rFar[a] = rcp * set1(1.0f + 0x1p-21f);
      const F qn0 = oAxis[a] * rNear[a], qf0 = oAxis[a] * rFar[a];
      qNear[a] = qn0 + ((qn0 & absMask) * set1(0x1p-22f) + set1(0x1p-100f));
      qFar[a] = qf0 - ((qf0 & absMask) * set1(0x1p-22f) + set1(0x1p-100f));
#else
      constexpr float kFarScale = 1.0f + 2.0f * (4.0f * 0x1p-24f) / (1.0f - 4.0f * 0x1p-24f);
      org[a] = oAxis[a];
      rdir[a] = rcp;
      rdirFar[a] = rcp * set1(kFarScale);
#endif
    }
#if RTR_BVH_AVX2
    const F inf = set1(kInf);
    F ok = set1(bitsFloat(0xFFFFFFFFu));
    for (int a = 0; a < 3; ++a)
      if (Parallel >> a & 1) {
        ok = ok & lt(oAxis[a] & absMask, inf);
        oLo[a] = allMin(oAxis[a]);
        oHi[a] = allMax(oAxis[a]);
      }
    for (int i = 0; i < kSlabs; ++i) {
      const int a = kSlabAxes.axis[i];
      ok = ok & lt(rNear[a] & absMask, inf) & lt(rFar[a] & absMask, inf) & lt(qNear[a] & absMask, inf) &
           lt(qFar[a] & absMask, inf) & neq(rNear[a], zero) & neq(rFar[a], zero);
      const unsigned signs = bits(neg[a]);
      if (signs != 0 && signs != 0xFFu) ok = set1(0.0f);
      // A product with a positive constant rounds monotonically: the bounds of rNear and rFar are the
      // bounds of the reciprocals times the same constants, two reductions fewer an axis.
      rnLo[a] = rcpLo[a] * set1(1.0f - 0x1p-21f);
      rnHi[a] = rcpHi[a] * set1(1.0f - 0x1p-21f);
      rfLo[a] = rcpLo[a] * set1(1.0f + 0x1p-21f);
      rfHi[a] = rcpHi[a] * set1(1.0f + 0x1p-21f);
      qnHi[a] = allMax(qNear[a]);
      qfLo[a] = allMin(qFar[a]);
      const int nearSide = signs ? 1 : 0;
      nearOff[a] = (nearSide * 3 + a) * 8;
      farOff[a] = ((1 - nearSide) * 3 + a) * 8;
    }
    interval = bits(ok) == 0xFFu;
#endif
  }

  // Whether every ray has the same watertight axis order (then leaves can be tested all rays at once);
  // the first call makes the shear constants, with Walker's operations for each ray.
  RTR_INLINE bool shear() {
    if (sheared) return sameShear;
    sheared = true;
    alignas(32) float so[3][8], ss[3][8];
    for (int i = 0; i < 8; ++i) {
      const Ray& ray = rays[i < nRays ? i : 0];
      const float* o = &ray.origin.x;
      const float* d = &ray.direction.x;
      int x, y, z;
      W::shearAxes(d, 1, x, y, z);
      if (i == 0) {
        kx = x;
        ky = y;
        kz = z;
      }
      sameShear = sameShear && x == kx && y == ky && z == kz;
      const float szs = 1.0f / d[z];
      so[0][i] = o[x];
      so[1][i] = o[y];
      so[2][i] = o[z];
      ss[0][i] = d[x] * szs;
      ss[1][i] = d[y] * szs;
      ss[2][i] = szs;
    }
    for (int a = 0; a < 3; ++a) {
      shO[a] = load(so[a]);
      shS[a] = load(ss[a]);
    }
    return sameShear;
  }

#if RTR_BVH_AVX2
  // The children of n that some ray of the packet may meet: never one that a ray's own test would visit
  // (the exact FMA rounds monotonically, so the bounds' FMA bounds every ray's; no operand is NaN).
  RTR_INLINE unsigned intervalHits(const Node& n, F tHitV) const {
    RTR_COUNT(c.intervalTests += 1);
    const float* b = &n.box[0][0][0];
    const F zero = set1(0.0f);
    F lo = zero, hi = allMax(tHitV);
    for (int i = 0; i < kSlabs; ++i) {
      const int a = kSlabAxes.axis[i];
      const F nb = load(b + nearOff[a]), fb = load(b + farOff[a]);
      lo = vmax(lo, fmsub(nb, sel(lt(nb, zero), rnHi[a], rnLo[a]), qnHi[a]));
      hi = vmin(hi, fmsub(fb, sel(lt(fb, zero), rfLo[a], rfHi[a]), qfLo[a]));
    }
    F in = le(lo, hi);
    for (int a = 0; a < 3; ++a)  // an axis the rays run parallel to: some origin within the slab
      if (Parallel >> a & 1) in = in & le(load(n.box[0][a]), oHi[a]) & ge(load(n.box[1][a]), oLo[a]);
    return bits(in);
  }
#endif

  // The rays of `active` (activeV: as a lane mask) whose box test passes child c of node n, with their
  // entry distances and the nearest of those (a vector minimum: a loop over the rays mispredicts).
  RTR_INLINE unsigned testChild(const Node& n, int c, [[maybe_unused]] unsigned active, F activeV, F tHitV, F& tNearOut,
                                float& nearest) const {
    RTR_COUNT(c.childTests += 1; c.childTestRays += unsigned(__builtin_popcount(active)));
    const F zero = set1(0.0f);
    F tn[3], tf[3];
    for (int i = 0; i < kSlabs; ++i) {
      const int a = kSlabAxes.axis[i];
      const F lo = set1(n.box[0][a][c]), hi = set1(n.box[1][a][c]);
      const F nearB = sel(neg[a], hi, lo), farB = sel(neg[a], lo, hi);
#if RTR_BVH_AVX2
      tn[i] = fmsub(nearB, rNear[a], qNear[a]);
      tf[i] = fmsub(farB, rFar[a], qFar[a]);
#else
      tn[i] = (nearB - org[a]) * rdir[a];
      tf[i] = (farB - org[a]) * rdirFar[a];
#endif
    }
    F tNear = zero, tFar = tHitV;  // the same min/max tree as Walker::visitNode
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
      if (Parallel >> a & 1) hitBox = hitBox & le(set1(n.box[0][a][c]), oAxis[a]) & ge(set1(n.box[1][a][c]), oAxis[a]);
    tNearOut = tNear;
    hitBox = hitBox & activeV;
    const unsigned m = bits(hitBox);
    if (m) nearest = minLane(sel(hitBox, tNear, set1(kInf)));
    return m;
  }

  // Tests node `ref`'s children against the packet: false when no ray meets any; else ref/active are
  // the child to visit next and its rays, the other children are on the stack.
  RTR_INLINE bool visitNode(PacketEntry* stack, int& sp, uint32_t& ref, unsigned& active) const {
    RTR_COUNT(c.packetNodes += 1; c.packetNodeRays += unsigned(__builtin_popcount(active)));
    const Node& n = bvh.nodes[ref];
    const F tHitV = load(cull);
    unsigned slots = bits(le(load(n.box[0][0]), load(n.box[1][0])));  // empty slots have lo > hi
#if RTR_BVH_AVX2
    if (interval) slots &= intervalHits(n, tHitV);
#endif
    F tn[8];
    unsigned mk[8];
    uint64_t keys[8];
    int k = 0;
    const F activeV = laneMask(active);
    for (; slots; slots &= slots - 1) {
      const int c = ctz(slots);
      F tNear;
      float mn;
      const unsigned m = testChild(n, c, active, activeV, tHitV, tNear, mn);
      if (!m) continue;
      // Order children by the nearest entry among their rays (farthest first for any hit, as Walker).
      const uint32_t d32 = floatBits(mn);
      const uint64_t key = uint64_t(AnyHit ? ~d32 : d32) << 32 | uint32_t(c);
      tn[c] = tNear;
      mk[c] = m;
      int j = k++;
      while (j > 0 && keys[j - 1] > key) {
        keys[j] = keys[j - 1];
        --j;
      }
      keys[j] = key;
    }
    if (k == 0) return false;
    for (int j = k - 1; j > 0; --j) {
      const int c = int(keys[j] & 7u);
      stack[sp++] = {tn[c], n.child[c], mk[c]};
    }
    const int c0 = int(keys[0] & 7u);
    ref = n.child[c0];
    active = mk[c0];
    return true;
  }

  // Closest hit: a candidate for ray i (see the top of this file).
  RTR_INLINE void offer(int i, float t, float b1, float b2, uint32_t prim) {
    if (t < best[i]) {
      second[i] = best[i];
      best[i] = t;
      hits[i] = {t, b1, b2, prim & ~Bvh::kNoShadowBit};
      const float c = t * (1.0f + 2.0f * kTieWindow);
      cull[i] = c < tMax[i] ? c : tMax[i];
    } else if (t < second[i]) {
      second[i] = t;
    }
  }

  // Closest hit: every candidate of ray i in leaf `ref`. Walker::testLeaf's operations, but against the
  // ray's own tMax, not the closest hit so far (a lane padding a short pack repeats the one before).
  RTR_INLINE void leafCandidates(int i, uint32_t ref) {
    const W& w = walker(i);
    const F zero = set1(0.0f), signBit = set1(-0.0f);
    const F tLimit = set1(cull[i] < tMax[i] ? cull[i] : tMax[i]);
    const uint32_t first = ref & 0x0FFFFFFFu, np = ((ref >> 28) & 7u) + 1;
    RTR_COUNT(c.leaves += 1);
    for (uint32_t p = first; p < first + np; ++p) {
      const TriPack& pk = bvh.packs[p];
      RTR_COUNT(c.packs += 1; c.triangles += unsigned(__builtin_popcount(realLanes(pk))));
      const F Az = load(pk.v[0][w.kz]) - w.oz, Bz = load(pk.v[1][w.kz]) - w.oz, Cz = load(pk.v[2][w.kz]) - w.oz;
      const F ax = (load(pk.v[0][w.kx]) - w.ox) - w.sx * Az, ay = (load(pk.v[0][w.ky]) - w.oy) - w.sy * Az;
      const F bx = (load(pk.v[1][w.kx]) - w.ox) - w.sx * Bz, by = (load(pk.v[1][w.ky]) - w.oy) - w.sy * Bz;
      const F cx = (load(pk.v[2][w.kx]) - w.ox) - w.sx * Cz, cy = (load(pk.v[2][w.ky]) - w.oy) - w.sy * Cz;
      const F U = cx * by - cy * bx, V = ax * cy - ay * cx, W3 = bx * ay - by * ax;
      unsigned edge = bits(eq(U, zero) | eq(V, zero) | eq(W3, zero));
      unsigned m = ~bits((U ^ V) | (V ^ W3)) & 0xFFu & ~edge;
      unsigned pad = 0;
      for (int lane = 1; lane < 8; ++lane) pad |= unsigned(pk.prim[lane] == pk.prim[lane - 1]) << lane;
      m &= ~pad;
      edge &= ~pad;
      if ((m | edge) == 0) continue;
      const F det = U + V + W3;
      const F T = U * (w.sz * Az) + V * (w.sz * Bz) + W3 * (w.sz * Cz);
      const F detSign = det & signBit;
      const F Ts = T ^ detSign;
      m &= bits(gt(Ts, zero) & lt(Ts, tLimit * (det ^ detSign)));  // det ≠ 0 here: Walker::testLeaf
      if (m) {
        const F inv = set1(1.0f) / det;
        alignas(32) float tv[8], iv[8], vv[8], wv[8];
        store(tv, T * inv);
        store(iv, inv);
        store(vv, V);
        store(wv, W3);
        for (; m; m &= m - 1) {
          const int lane = ctz(m);
          const float t = tv[lane];
          if (t > 0.0f && t < tMax[i]) offer(i, t, vv[lane] * iv[lane], wv[lane] * iv[lane], pk.prim[lane]);
        }
      }
      for (; edge; edge &= edge - 1) {
        const int lane = ctz(edge);
        WatertightRay r(rays[i]);
        float b1, b2;
        const float t = intersectWatertight(r, laneTriangle(pk, lane), b1, b2);
        if (t > 0.0f) offer(i, t, b1, b2, pk.prim[lane]);
      }
    }
  }

  // Triangle `lane` of pk against the `active` rays at once, each lane with exactly Walker::testLeaf's
  // operations for its ray: m, the rays that meet it in (0, tLimit); edge, those exactly on an edge in
  // float (for the scalar test); det, T, V, W3 for t and the barycentrics. False: neither.
  struct Lanes {
    unsigned m, edge;
    F det, T, V, W3;
  };
  RTR_INLINE bool triangleRays(const TriPack& pk, int lane, unsigned active, F tLimit, Lanes& o) const {
    const F zero = set1(0.0f), signBit = set1(-0.0f);
    const F Az = set1(pk.v[0][kz][lane]) - shO[2], Bz = set1(pk.v[1][kz][lane]) - shO[2], Cz = set1(pk.v[2][kz][lane]) - shO[2];
    const F ax = (set1(pk.v[0][kx][lane]) - shO[0]) - shS[0] * Az, ay = (set1(pk.v[0][ky][lane]) - shO[1]) - shS[1] * Az;
    const F bx = (set1(pk.v[1][kx][lane]) - shO[0]) - shS[0] * Bz, by = (set1(pk.v[1][ky][lane]) - shO[1]) - shS[1] * Bz;
    const F cx = (set1(pk.v[2][kx][lane]) - shO[0]) - shS[0] * Cz, cy = (set1(pk.v[2][ky][lane]) - shO[1]) - shS[1] * Cz;
    const F U = cx * by - cy * bx, V = ax * cy - ay * cx, W3 = bx * ay - by * ax;
    o.edge = bits(eq(U, zero) | eq(V, zero) | eq(W3, zero)) & active;
    o.m = ~bits((U ^ V) | (V ^ W3)) & active & ~o.edge;
    if ((o.m | o.edge) == 0) return false;
    o.det = U + V + W3;
    o.T = U * (shS[2] * Az) + V * (shS[2] * Bz) + W3 * (shS[2] * Cz);
    const F detSign = o.det & signBit;
    const F Ts = o.T ^ detSign;
    o.m &= bits(gt(Ts, zero) & lt(Ts, tLimit * (o.det ^ detSign)));  // det ≠ 0 here: Walker::testLeaf
    o.V = V;
    o.W3 = W3;
    return true;
  }

  // Any hit: the rays of `active` that triangle `lane` of pk occludes (tLimit: their tMax).
  RTR_INLINE unsigned occludedBy(const TriPack& pk, int lane, unsigned active, F tLimit) const {
    Lanes l;
    if (!triangleRays(pk, lane, active, tLimit, l)) return 0;
    unsigned occluded = l.m;
    for (unsigned edge = l.edge; edge; edge &= edge - 1) {
      const int i = ctz(edge);
      WatertightRay r(rays[i]);
      float b1, b2;
      if (intersectWatertight(r, laneTriangle(pk, lane), b1, b2) > 0.0f) occluded |= 1u << i;
    }
    return occluded;
  }

  // Leaf `ref` with lanes = rays: each real triangle against all `active` rays at once (triangleRays;
  // closest hit: leafCandidates' rules). Any hit: returns the rays found occluded.
  RTR_INLINE unsigned leafAllRays(uint32_t ref, unsigned active) {
    const uint32_t first = ref & 0x0FFFFFFFu, np = ((ref >> 28) & 7u) + 1;
    unsigned occluded = 0;
    for (uint32_t p = first; p < first + np; ++p) {
      const TriPack& pk = bvh.packs[p];
      unsigned tris = realLanes(pk);
      if constexpr (AnyHit) tris &= ~topBits(pk.prim);  // shadow casters only
      const F tLimit = load(AnyHit ? tMax : cull);      // cull ≤ tMax (offer)
      for (; tris; tris &= tris - 1) {
        const int lane = ctz(tris);
        RTR_COUNT(c.triangleTests += 1; c.packetTriangles += unsigned(__builtin_popcount(active)));
        if constexpr (AnyHit) {
          const unsigned occ = occludedBy(pk, lane, active, tLimit);
          if (!occ) continue;
          occluded |= occ;
          active &= ~occ;
          if (!active) return occluded;
          continue;
        }
        Lanes l;
        if (!triangleRays(pk, lane, active, tLimit, l)) continue;
        if (l.m) {
          const F inv = set1(1.0f) / l.det;
          alignas(32) float tv[8], iv[8], vv[8], wv[8];
          store(tv, l.T * inv);
          store(iv, inv);
          store(vv, l.V);
          store(wv, l.W3);
          for (unsigned m = l.m; m; m &= m - 1) {
            const int i = ctz(m);
            const float t = tv[i];
            if (t > 0.0f && t < tMax[i]) offer(i, t, vv[i] * iv[i], wv[i] * iv[i], pk.prim[lane]);
          }
        }
        for (unsigned edge = l.edge; edge; edge &= edge - 1) {
          const int i = ctz(edge);
          WatertightRay r(rays[i]);
          float b1, b2;
          const float t = intersectWatertight(r, laneTriangle(pk, lane), b1, b2);
          if (t > 0.0f) offer(i, t, b1, b2, pk.prim[lane]);
        }
      }
    }
    return occluded;
  }

  // Closest hit, ray i alone: one node or one leaf of its walk (every candidate of a leaf offered, the
  // cull distance then its new one); false when the walk is over.
  RTR_INLINE bool aloneStep(int i, const W& w, uint64_t* stack, Cursor& at) {
    if (!(at.ref & Bvh::kLeafBit)) {
      if (w.visitNode(stack, at, set1(at.tHit))) return true;
    } else {
      leafCandidates(i, at.ref);
      at.tHit = cull[i];
    }
    return W::pop(stack, at);
  }

  // Ray i alone from node or leaf `ref` on: its single-ray walk; returns whether it is occluded (any hit).
  RTR_INLINE bool alone(int i, uint32_t ref) {
    RTR_COUNT(c.lone += 1);
    const W& w = walker(i);
    uint64_t stack[kStackSize];
    if constexpr (AnyHit) {
      Cursor at{0, ref, tMax[i], false};
      Hit scratch;
      return w.run(stack, at, scratch);
    } else {
      Cursor at{0, ref, cull[i], false};
      while (aloneStep(i, w, stack, at)) {}
      return false;
    }
  }

  // Rays a and b alone from node or leaf `ref` on, one node or leaf of each in turn, as
  // Bvh::occludedPair: while one waits for memory the other works. Any hit: returns the rays found occluded.
  RTR_INLINE unsigned alonePair(int a, int b, uint32_t ref) {
    RTR_COUNT(c.lone += 2);
    const W& wa = walker(a);
    const W& wb = walker(b);
    uint64_t stackA[kStackSize], stackB[kStackSize];
    if constexpr (AnyHit) {
      Cursor atA{0, ref, tMax[a], false}, atB{0, ref, tMax[b], false};
      Hit scratch;
      bool moreA = true, moreB = true;
      while (moreA && moreB) {
        moreA = wa.step(stackA, atA, scratch);
        moreB = wb.step(stackB, atB, scratch);
      }
      if (moreA) wa.run(stackA, atA, scratch);
      if (moreB) wb.run(stackB, atB, scratch);
      return unsigned(atA.found) << a | unsigned(atB.found) << b;
    } else {
      Cursor atA{0, ref, cull[a], false}, atB{0, ref, cull[b], false};
      bool moreA = true, moreB = true;
      while (moreA && moreB) {
        moreA = aloneStep(a, wa, stackA, atA);
        moreB = aloneStep(b, wb, stackB, atB);
      }
      while (moreA) moreA = aloneStep(a, wa, stackA, atA);
      while (moreB) moreB = aloneStep(b, wb, stackB, atB);
      return 0;
    }
  }

  // Walks the packet; any hit: returns the occluded rays; closest hit: the rays to trace again alone.
  RTR_INLINE unsigned run(unsigned active) {
    PacketEntry stack[kStackSize];
    int sp = 0;
    uint32_t ref = bvh.root;
    unsigned done = 0;  // any hit: the rays already occluded
    for (;;) {
      for (;;) {
        if (__builtin_popcount(active) <= aloneRays) {  // too few rays to share the work
          while (active) {
            const int i = ctz(active);
            active &= active - 1;
            if (active) {
              const int j = ctz(active);
              active &= active - 1;
              done |= alonePair(i, j, ref);
            } else if (alone(i, ref)) {
              done |= 1u << i;
            }
          }
          break;
        }
        if (ref & Bvh::kLeafBit) {
          RTR_COUNT(c.packetLeaves += 1; c.packetLeafRays += unsigned(__builtin_popcount(active)));
          if (__builtin_popcount(active) >= leafRays && shear()) {
            done |= leafAllRays(ref, active);
            break;
          }
          for (unsigned b = active; b; b &= b - 1) {
            const int i = ctz(b);
            if constexpr (AnyHit) {
              Cursor at{0, ref, tMax[i], false};
              Hit scratch;
              if (walker(i).testLeaf(at, scratch, set1(tMax[i]))) done |= 1u << i;
            } else {
              leafCandidates(i, ref);
            }
          }
          break;
        }
        if (!visitNode(stack, sp, ref, active)) break;
        if (AnyHit) active &= ~done;
        if (!active) break;
      }
      for (;;) {
        if (sp == 0) {
          if constexpr (AnyHit) return done;
          unsigned retry = 0;
          for (int i = 0; i < 8; ++i)
            if (best[i] < kInf && !(second[i] > best[i] * (1.0f + kTieWindow))) retry |= 1u << i;
          return retry;
        }
        const PacketEntry& e = stack[--sp];
        active = e.mask & bits(ngt(e.tNear, load(cull))) & ~done;
        if (active) {
          ref = e.ref;
          break;
        }
      }
    }
  }
};

template <bool AnyHit, unsigned Parallel>
unsigned walkPacket(const Bvh::View& bvh, const Ray* rays, int n, const PacketRays& pr, IntersectMethod method, Hit* hits,
                    int leafRays, int aloneRays) {
  RTR_COUNT(c.packets += 1);
  PacketWalker<AnyHit, Parallel> p(bvh, rays, n, pr, hits, method, leafRays, aloneRays);
  return p.run((1u << n) - 1);
}

#undef RTR_INLINE
