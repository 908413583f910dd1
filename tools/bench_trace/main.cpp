// bench-trace: BVH build time and Mrays/s of primary, shadow (any hit) and mirror rays, ours against
// Embree 3 (rtcIntersect1 / rtcOccluded1, build quality high), same mesh, same rays, same thread count,
// in one run; plus the agreement of the two and the intersection routines' speed against their errors.
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <functional>
#include <initializer_list>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <embree3/rtcore.h>

#include <glm/common.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec3.hpp>

#include "core/camera.hpp"
#include "core/parallel.hpp"
#include "scene/load.hpp"
#include "trace/bvh.hpp"
#include "trace/procedural.hpp"
#include "trace/spawn.hpp"
#include "rays.hpp"

using namespace rtr;
using namespace rtr::trace;
using Clock = std::chrono::steady_clock;

namespace {

double seconds(Clock::time_point a) { return std::chrono::duration<double>(Clock::now() - a).count(); }

// --cpu-time: time by the threads' CPU time (summed, divided by the thread count) instead of the wall
// clock. For A/B runs on a shared, oversubscribed machine (the project VM): the time a thread waits
// for a core is left out; its caches shared with other work are not.
bool gCpuTime = false;

double threadSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// Runs f(i) for i in [0, n) over `threads` threads in pieces of 256; returns the best of `reps` wall times.
// Each piece sums f's results privately: one shared sink written per ray would bounce its cache line
// between the cores and cap both tracers at the same rate.
double timed(size_t n, unsigned threads, int reps, const std::function<uint32_t(size_t)>& f) {
  static std::atomic<uint32_t> sink{0};
  constexpr size_t kPiece = 256;
  double best = 1e30;
  for (int r = 0; r < reps; ++r) {
    const auto start = Clock::now();
    std::atomic<int64_t> cpuNs{0};
    parallelFor((n + kPiece - 1) / kPiece, threads, [&](size_t p) {
      const FlushDenormals flush;
      const double t0 = gCpuTime ? threadSeconds() : 0.0;
      uint32_t acc = 0;
      for (size_t i = p * kPiece; i < std::min(n, (p + 1) * kPiece); ++i) acc += f(i);
      sink.fetch_add(acc, std::memory_order_relaxed);
      if (gCpuTime) cpuNs.fetch_add(int64_t((threadSeconds() - t0) * 1e9), std::memory_order_relaxed);
    });
    best = std::min(best, gCpuTime ? 1e-9 * double(cpuNs.load()) / double(threads) : seconds(start));
  }
  return best;
}

struct Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  double buildSeconds = 0;
  Embree(const std::vector<Triangle>& tris, unsigned threads) {
    const std::string cfg = "threads=" + std::to_string(threads);
    device = rtcNewDevice(cfg.c_str());
    scene = rtcNewScene(device);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
    float* v = (float*)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, tris.size() * 3);
    unsigned* idx = (unsigned*)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, tris.size());
    for (size_t i = 0; i < tris.size(); ++i) {
      std::memcpy(v + i * 9, &tris[i].v0, 12);
      std::memcpy(v + i * 9 + 3, &tris[i].v1, 12);
      std::memcpy(v + i * 9 + 6, &tris[i].v2, 12);
      idx[i * 3] = unsigned(i * 3);
      idx[i * 3 + 1] = unsigned(i * 3 + 1);
      idx[i * 3 + 2] = unsigned(i * 3 + 2);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    const auto start = Clock::now();
    rtcCommitScene(scene);
    buildSeconds = seconds(start);
  }
  ~Embree() {
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
  }
  Hit closest(const Ray& r) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh{};
    rh.ray.org_x = r.origin.x;
    rh.ray.org_y = r.origin.y;
    rh.ray.org_z = r.origin.z;
    rh.ray.dir_x = r.direction.x;
    rh.ray.dir_y = r.direction.y;
    rh.ray.dir_z = r.direction.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = r.tMax;
    rh.ray.mask = ~0u;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &ctx, &rh);
    Hit h;
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) h = {rh.ray.tfar, rh.hit.u, rh.hit.v, rh.hit.primID};
    return h;
  }
  // Packets of eight rays (rtcIntersect8/Occluded8, Embree's SIMD packet traversal): the n ≤ 8 rays at r.
  bool packets() const { return rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) != 0; }
  static void fill8(const Ray* r, int n, int (&valid)[8], RTCRay8& ray) {
    for (int k = 0; k < 8; ++k) {
      const Ray& q = r[k < n ? k : 0];
      valid[k] = k < n ? -1 : 0;
      ray.org_x[k] = q.origin.x;
      ray.org_y[k] = q.origin.y;
      ray.org_z[k] = q.origin.z;
      ray.dir_x[k] = q.direction.x;
      ray.dir_y[k] = q.direction.y;
      ray.dir_z[k] = q.direction.z;
      ray.tnear[k] = 0.0f;
      ray.tfar[k] = q.tMax;
      ray.mask[k] = ~0u;
      ray.time[k] = 0.0f;
      ray.flags[k] = 0;
    }
  }
  uint32_t closest8(const Ray* r, int n) const {
    alignas(32) int valid[8];
    alignas(32) RTCRayHit8 rh;
    fill8(r, n, valid, rh.ray);
    for (int k = 0; k < 8; ++k) rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    rtcIntersect8(valid, scene, &ctx, &rh);
    uint32_t acc = 0;
    for (int k = 0; k < n; ++k) acc += rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID ? rh.hit.primID[k] : kNoHit;
    return acc;
  }
  uint32_t occluded8(const Ray* r, int n) const {
    alignas(32) int valid[8];
    alignas(32) RTCRay8 ray;
    fill8(r, n, valid, ray);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    rtcOccluded8(valid, scene, &ctx, &ray);
    uint32_t acc = 0;
    for (int k = 0; k < n; ++k) acc += ray.tfar[k] < 0.0f;
    return acc;
  }
  bool occluded(const Ray& r) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray{};
    ray.org_x = r.origin.x;
    ray.org_y = r.origin.y;
    ray.org_z = r.origin.z;
    ray.dir_x = r.direction.x;
    ray.dir_y = r.direction.y;
    ray.dir_z = r.direction.z;
    ray.tnear = 0.0f;
    ray.tfar = r.tMax;
    ray.mask = ~0u;
    rtcOccluded1(scene, &ctx, &ray);
    return ray.tfar < 0.0f;
  }
};

std::vector<Triangle> trianglesOf(const Scene& s) {
  std::vector<Triangle> t;
  for (const Mesh& m : s.meshes)
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3)
      t.push_back({m.positions[m.indices[i]], m.positions[m.indices[i + 1]], m.positions[m.indices[i + 2]]});
  return t;
}

// Why a hit/miss disagreement happens: the triangle that one side hit, the watertight test's edge
// functions for it (in float, as the scalar routine computes them), the edge the ray passes nearest and
// whether another triangle shares that edge (same vertex positions). Counted by kind in `kinds`.
// Whether the ray meets the triangle (edges included) in front of its origin, all in double precision.
bool meetsInDouble(const Ray& r, const Triangle& t) {
  const WatertightRay w(r);
  const glm::dvec3 o(r.origin), d(r.direction);
  const double sx = d[w.kx] / d[w.kz], sy = d[w.ky] / d[w.kz];
  double x[3], y[3], z[3];
  const glm::vec3 v[3] = {t.v0, t.v1, t.v2};
  for (int i = 0; i < 3; ++i) {
    const glm::dvec3 a = glm::dvec3(v[i]) - o;
    x[i] = a[w.kx] - sx * a[w.kz];
    y[i] = a[w.ky] - sy * a[w.kz];
    z[i] = a[w.kz] / d[w.kz];
  }
  const double e0 = x[2] * y[1] - y[2] * x[1], e1 = x[0] * y[2] - y[0] * x[2], e2 = x[1] * y[0] - y[1] * x[0];
  const double det = e0 + e1 + e2;
  if (det == 0.0 || !((e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0))) return false;
  return (e0 * z[0] + e1 * z[1] + e2 * z[2]) / det > 0.0;
}

void explain(const Ray& r, const Hit& ours, const Hit& theirs, const std::vector<Triangle>& tris, bool print,
             std::map<std::string, size_t>& kinds) {
  const Hit& h = ours.hit() ? ours : theirs;
  const Triangle& t = tris[h.prim];
  const WatertightRay w(r);
  const glm::vec3 A = t.v0 - r.origin, B = t.v1 - r.origin, C = t.v2 - r.origin;
  const float ax = A[w.kx] - w.sx * A[w.kz], ay = A[w.ky] - w.sy * A[w.kz];
  const float bx = B[w.kx] - w.sx * B[w.kz], by = B[w.ky] - w.sy * B[w.kz];
  const float cx = C[w.kx] - w.sx * C[w.kz], cy = C[w.ky] - w.sy * C[w.kz];
  const float e[3] = {cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax};  // opposite v0, v1, v2
  const glm::vec3 v[3] = {t.v0, t.v1, t.v2};
  const float sum = std::fabs(e[0]) + std::fabs(e[1]) + std::fabs(e[2]);
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (std::fabs(e[i]) < std::fabs(e[k])) k = i;
  const float rel = std::fabs(e[k]) / sum;  // 0: exactly on the edge in float
  const glm::vec3 p = v[(k + 1) % 3], q = v[(k + 2) % 3];
  int neighbours = 0;
  bool meets = meetsInDouble(r, t);
  for (uint32_t i = 0; i < tris.size(); ++i) {
    if (i == h.prim) continue;
    int shared = 0;
    for (const glm::vec3& c : {tris[i].v0, tris[i].v1, tris[i].v2}) shared += c == p || c == q;
    if (shared < 2) continue;
    ++neighbours;
    meets = meets || meetsInDouble(r, tris[i]);
  }
  std::string kind = ours.hit() ? "only ours hits" : "only Embree hits";
  kind += rel == 0.0f ? ", exactly on an edge" : rel < 1e-5f ? ", within 1e-5 of an edge" : ", away from edges";
  if (rel < 1e-5f) kind += neighbours ? " another triangle shares" : " of an open mesh (no other triangle shares it)";
  kind += meets ? "; in double precision the ray meets it or a triangle across that edge"
                : "; in double precision the ray meets neither it nor a triangle across that edge";
  ++kinds[kind];
  if (print)
    std::printf("    triangle %u, t %.9g, edge functions %.3g %.3g %.3g: %s\n", h.prim, h.t, e[0], e[1], e[2], kind.c_str());
}

// What each ray costs in work, single rays and packets of eight (BvhCounters, the counting traversal on
// one thread; the counts do not depend on the machine): where a row stays below Embree's packets, these
// say whether nodes, leaves or idle SIMD lanes bound it. An 8-wide pass: one ray against a node's eight
// boxes or a pack's eight triangles, or one box or triangle against a packet's eight lanes.
void printCounters(const Bvh& bvh, const std::vector<RaySet>& sets) {
  Bvh::setCounting(true);
  std::printf(
      "\nWork per ray (counted; a pass: one 8-wide box or triangle test, lanes = boxes or triangles for one ray, "
      "or lanes = rays for a packet; `live`: the share of a packet's 8 lanes with a ray):\n\n"
      "| rays | single: node visits | packs | triangles | packets: node visits a packet | box tests a node visit | "
      "live at box tests | leaf visits a packet | live at leaves | box passes a ray: single / packets | "
      "triangle passes a ray: single / packets (of them lanes = rays) | walks alone a ray | retried |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const RaySet& s : sets) {
    const std::vector<Ray>& rays = *s.rays;
    const double n = double(std::max<size_t>(1, rays.size()));
    Bvh::counters() = {};
    for (const Ray& r : rays) s.any ? void(bvh.occluded(r)) : void(bvh.closest(r));
    const BvhCounters one = Bvh::counters();
    Bvh::counters() = {};
    for (size_t i = 0; i < rays.size(); i += 8) {
      const int k = int(std::min<size_t>(8, rays.size() - i));
      Hit h[8];
      if (s.any) bvh.occluded8(&rays[i], k);
      else bvh.closest8(&rays[i], k, h, IntersectMethod::Watertight, s.kind);
    }
    const BvhCounters p = Bvh::counters();
    auto share = [](uint64_t live, uint64_t visits) { return visits ? double(live) / (8.0 * double(visits)) : 0.0; };
    // Packets' passes: their box and triangle tests plus the single-ray work of rays walking alone, retried,
    // or testing a leaf ray by ray.
    std::printf(
        "| %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.0f %% | %.2f | %.0f %% | %.2f / %.2f | %.2f / %.2f (%.2f) | %.3f | %.4f |\n",
        s.name, one.nodes / n, one.packs / n, one.triangles / n, 8.0 * p.packetNodes / n,
        p.packetNodes ? double(p.childTests) / double(p.packetNodes) : 0.0, 100.0 * share(p.childTestRays, p.childTests),
        8.0 * p.packetLeaves / n, 100.0 * share(p.packetLeafRays, p.packetLeaves), one.nodes / n,
        (p.intervalTests + p.childTests + p.nodes) / n, one.packs / n, (p.triangleTests + p.packs) / n, p.triangleTests / n,
        p.lone / n, p.retries / n);
  }
  Bvh::counters() = {};
  Bvh::setCounting(false);
}

struct Options {
  unsigned threads = threadCount();
  int res = 1024, reps = 3, leafRays = Bvh::kPacketLeafRays;
  int aloneRays[3] = {Bvh::kPacketAloneRays[0], Bvh::kPacketAloneRays[1], Bvh::kPacketAloneRays[2]};
  std::vector<int> aloneSweep;                        // --alone-sweep: our packets timed with each of these, same turns
  std::vector<int> mirrorTiles;                       // --mirror-tiles: the mirror rays also regrouped per tile of each size
  std::vector<std::pair<uint32_t, uint32_t>> grains;  // --build-grain: also built with each (Bvh::setBuildGrain)
  bool quick = false, explainAll = false, countOnly = false;
  bool packetsOnly = false;  // time only the packets, ours and Embree's; no agreement with Embree
  bool singlesOnly = false;  // time only single rays and pairs, ours, and rtcIntersect1/Occluded1
  bool buildOnly = false;    // time only the builds, ours and Embree's alternately
  bool profile = false;      // where a packet's time goes (printProfile)
};

// FNV-1a over the tree's nodes and packs (field by field: a Node has padding): equal hashes from two
// binaries say they built the same tree.
uint64_t treeHash(const Bvh& bvh) {
  uint64_t h = 1469598103934665603ull;
  const auto add = [&h](const void* p, size_t n) {
    for (size_t i = 0; i < n; ++i) h = (h ^ static_cast<const unsigned char*>(p)[i]) * 1099511628211ull;
  };
  const Bvh::View v = bvh.view();
  add(&v.root, sizeof v.root);
  for (uint32_t i = 0; i < bvh.stats().nodes; ++i) {
    add(v.nodes[i].box, sizeof v.nodes[i].box);
    add(v.nodes[i].child, sizeof v.nodes[i].child);
  }
  for (uint32_t i = 0; i < bvh.stats().packs; ++i) {
    add(v.packs[i].v, sizeof v.packs[i].v);
    add(v.packs[i].prim, sizeof v.packs[i].prim);
  }
  return h;
}

// --build-only: ours and Embree's builds alternately, every rep's phases, and the tree's hash.
void benchBuilds(const std::vector<Triangle>& tris, const Options& o) {
  for (int rep = 0; rep < o.reps; ++rep) {
    const auto t0 = Clock::now();
    const double c0 = threadSeconds();
    const Bvh bvh(tris, {}, o.threads);
    // --cpu-time with one thread: the builder's CPU time (it runs on this thread), for A/B runs on a busy machine
    const double ours = gCpuTime && o.threads == 1 ? threadSeconds() - c0 : seconds(t0);
    const Embree em(tris, o.threads);
    const BvhStats& st = bvh.stats();
    std::printf(
        "build %u threads: ours %.4f s (references %.4f, tree %.4f, copy-out %.4f), Embree %.4f s, ratio %.2f; "
        "SAH cost %.4f, %u nodes, %u packs, tree hash %016llx\n",
        o.threads, ours, st.refSeconds, st.treeSeconds, st.buildSeconds - st.refSeconds - st.treeSeconds, em.buildSeconds,
        ours / em.buildSeconds, bvh.sahCost(), st.nodes, st.packs, (unsigned long long)treeHash(bvh));
    for (const auto& [task, chunk] : o.grains) {  // the same tree, other grains: timed right after
      Bvh::setBuildGrain(task, chunk);
      const auto t1 = Clock::now();
      const Bvh other(tris, {}, o.threads);
      const double s = seconds(t1);
      Bvh::setBuildGrain(Bvh::kSubtreeTask, Bvh::kParallelChunk);
      std::printf("  grain %u/%u (subtree task / chunk): ours %.4f s (tree %.4f), ratio %.2f%s\n", task, chunk, s,
                  other.stats().treeSeconds, s / em.buildSeconds, treeHash(other) == treeHash(bvh) ? "" : ", ANOTHER TREE");
    }
  }
}

// Ours and Embree's build, with ours on one thread too (the same tree: the parallel build's speed-up).
void printBuilds(const std::vector<Triangle>& tris, const Bvh& bvh, double ourBuild, const Embree& em, unsigned threads) {
  double oneThread = 0.0;
  if (threads != 1) {
    const auto t1 = Clock::now();
    const Bvh serial(tris, {}, 1);
    oneThread = seconds(t1);
  }
  const BvhStats& st = bvh.stats();
  std::printf(
      "BVH build: ours %.3f s (%u nodes, %u packs, depth %u, SAH cost %.4f; references %.3f s, tree %.3f s, "
      "copy-out %.3f s; 1 thread %.3f s); Embree (quality high) %.3f s\n"
      "Our tree's memory: nodes %zu B each, %.1f MB; triangle packs %zu B each, %.1f MB\n\n",
      ourBuild, st.nodes, st.packs, st.maxDepth, bvh.sahCost(), st.refSeconds, st.treeSeconds,
      st.buildSeconds - st.refSeconds - st.treeSeconds, oneThread, em.buildSeconds, sizeof(Node),
      double(st.nodes) * sizeof(Node) * 1e-6, sizeof(TriPack), double(st.packs) * sizeof(TriPack) * 1e-6);
}

// Hit/miss and distance agreement with Embree on the primary, orthographic and mirror rays (and shadow rays).
void printAgreement(const std::vector<Triangle>& tris, const Bvh& bvh, const Embree& em, const Rays& rays, bool explainAll) {
  const std::vector<Ray>&primary = rays.primary, &ortho = rays.ortho, &mirror = rays.mirror, &shadow = rays.shadow;
  for (auto* set : {&primary, &ortho, &mirror}) {
    size_t disagree = 0, otherTriangle = 0, farOff = 0;
    double maxRel = 0, maxRelSame = 0;
    std::map<std::string, size_t> kinds;
    for (const Ray& r : *set) {
      const Hit a = bvh.closest(r), b = em.closest(r);
      if (a.hit() != b.hit()) {
        explain(r, a, b, tris, explainAll, kinds);
        ++disagree;
        continue;
      }
      if (!a.hit()) continue;
      const double rel = std::fabs(double(a.t) - double(b.t)) / std::max(1e-30, double(b.t));
      maxRel = std::max(maxRel, rel);
      farOff += rel > 1e-4;
      if (a.prim != b.prim) ++otherTriangle;
      else maxRelSame = std::max(maxRelSame, rel);
    }
    for (const auto& [kind, n] : kinds) std::printf("  (%zu: %s)\n", n, kind.c_str());
    std::printf(
        "  (%zu rays hit another triangle than Embree's; %zu differ in t by more than 1e-4 relative; "
        "same triangle: largest relative t difference %.3g)\n",
        otherTriangle, farOff, maxRelSame);
    size_t shadowDisagree = 0;
    if (set == &primary)
      for (const Ray& r : shadow) shadowDisagree += bvh.occluded(r) != em.occluded(r);
    std::printf("agreement with Embree, %s rays: %zu hit/miss disagreements of %zu, largest relative t difference %.3g%s\n",
                set == &primary ? "primary"
                : set == &ortho ? "orthographic primary"
                                : "mirror",
                disagree, set->size(), maxRel,
                set == &primary ? (", shadow rays: " + std::to_string(shadowDisagree) + " disagreements").c_str() : "");
  }
}

// Our packets and Embree's against single rays: the same answers, bit for bit.
void printPacketAgreement(const Bvh& bvh, const Embree& em, const Rays& rays, int leafRays) {
  const std::vector<Ray>&primary = rays.primary, &ortho = rays.ortho, &mirror = rays.mirror, &shadow = rays.shadow;
  if (em.packets()) {  // the packets give the same answers as rtcIntersect1/Occluded1 (summed per packet)
    size_t differ = 0, total = 0;
    for (auto* set : {&primary, &shadow, &mirror})
      for (size_t i = 0; i < set->size(); i += 8, ++total) {
        const int n = int(std::min<size_t>(8, set->size() - i));
        uint32_t one = 0;
        for (int k = 0; k < n; ++k) one += set == &shadow ? uint32_t(em.occluded((*set)[i + k])) : em.closest((*set)[i + k]).prim;
        differ += one != (set == &shadow ? em.occluded8(&(*set)[i], n) : em.closest8(&(*set)[i], n));
      }
    std::printf("\nEmbree's packets of 8 against its single rays: %zu of %zu packets differ\n", differ, total);
  }
  // Our packets against our single rays, every ray of every set: t, barycentrics and triangle bit for bit;
  // with leaves tested all rays at once wherever two rays reach them, and as set (--leaf-rays).
  for (int lr : {2, leafRays}) {
    Bvh::setPacketLeafRays(lr);
    size_t differ = 0, total = 0;
    for (auto* set : {&primary, &ortho, &shadow, &mirror})
      for (size_t i = 0; i < set->size(); i += 8) {
        const int n = int(std::min<size_t>(8, set->size() - i));
        Hit h[8];
        if (set != &shadow)
          bvh.closest8(&(*set)[i], n, h, IntersectMethod::Watertight,
                       set == &mirror ? PacketKind::Scattered : PacketKind::Coherent);
        const unsigned occ = set == &shadow ? bvh.occluded8(&(*set)[i], n) : 0u;
        for (int k = 0; k < n; ++k, ++total) {
          if (set == &shadow) {
            differ += ((occ >> k) & 1) != unsigned(bvh.occluded((*set)[i + k]));
            continue;
          }
          const Hit one = bvh.closest((*set)[i + k]);
          differ += std::memcmp(&one, &h[k], sizeof one) != 0;
        }
      }
    std::printf(
        "Our packets of 8 (leaves all rays at once from %d live rays) against our single rays (primary, orthographic, "
        "shadow, mirror): %zu of %zu rays differ\n",
        lr, differ, total);
  }
  // Every single ray's answer hashed (FNV-1a over t, barycentrics and triangle; occluded or not): equal
  // hashes from two binaries say a change of the tree's layout changed no hit.
  uint64_t h = 1469598103934665603ull;
  const auto add = [&h](const void* p, size_t n) {
    for (size_t i = 0; i < n; ++i) h = (h ^ static_cast<const unsigned char*>(p)[i]) * 1099511628211ull;
  };
  for (auto* set : {&primary, &ortho, &shadow, &mirror})
    for (const Ray& r : *set) {
      if (set == &shadow) {
        const bool occ = bvh.occluded(r);
        add(&occ, 1);
        continue;
      }
      const Hit one = bvh.closest(r);
      add(&one, sizeof one);
    }
  std::printf("Hash of our single rays' answers (primary, orthographic, shadow, mirror): %016llx\n", (unsigned long long)h);
}

// The speed table, on one and on all threads. Ours: one ray at a time (Bvh::closest, as rtcIntersect1), two
// rays in flight (Bvh::closestPair, as the tracer traces primary rays) and packets of eight; the goal's
// ratio is against rtcIntersect1, Embree's packets (rtcIntersect8) are there for comparison.
void printSpeeds(const Bvh& bvh, const Embree& em, const Rays& all, const Options& o) {
  const unsigned threads = o.threads;
  const int reps = o.reps, leafRays = o.leafRays;
  const bool packets = em.packets();
  std::printf(
      "\n| rays | threads | ours, 1 ray at a time (Mrays/s) | ours, 2 rays in flight | ours, packets of 8, leaves ray by ray "
      "| ours, packets of 8 (leaves all rays at once from %d live; single rays from %d / %d / %d live: coherent / "
      "scattered / any hit) | Embree rtcIntersect1/Occluded1 "
      "| Embree rtcIntersect8/Occluded8 | 1 at a time / Embree | ours / Embree | our packets / Embree packets |\n",
      leafRays, o.aloneRays[0], o.aloneRays[1], o.aloneRays[2]);
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::vector<unsigned> counts{1};
  if (threads > 1) counts.push_back(threads);
  std::string sweepLines;  // --alone-sweep, printed after the table
  for (unsigned th : counts) {
    for (const RaySet& s : all.sets()) {
      const auto& rays = *s.rays;
      const size_t pairs = rays.size() / 2;  // an odd last ray goes alone
      // Alternate the four, best of each: a machine that slows down for a while slows all. Each turn
      // runs twice, so that the best run finds its own BVH in the caches, not the other's.
      double single = 1e30, paired = 1e30, ours8 = 1e30, ours8r = 1e30, theirs = 1e30, theirs8 = 1e30;
      std::vector<double> sweep(o.aloneSweep.size(), 1e30);
      for (int r = 0; r < reps; ++r) {
        if (!o.packetsOnly)
          single = std::min(single, timed(rays.size(), th, 2, [&](size_t i) {
                              return s.any ? uint32_t(bvh.occluded(rays[i])) : bvh.closest(rays[i]).prim;
                            }));
        if (!o.packetsOnly)
          paired = std::min(paired, timed(pairs + rays.size() % 2, th, 2, [&](size_t i) {
                              if (i == pairs) return s.any ? uint32_t(bvh.occluded(rays[2 * i])) : bvh.closest(rays[2 * i]).prim;
                              const std::array<Ray, 2> two{rays[2 * i], rays[2 * i + 1]};
                              if (s.any) {
                                const auto o = bvh.occludedPair(two);
                                return uint32_t(o[0]) + uint32_t(o[1]);
                              }
                              const auto h = bvh.closestPair(two);
                              return h[0].prim + h[1].prim;
                            }));
        auto packets8 = [&](size_t i) {
          const int n = int(std::min<size_t>(8, rays.size() - 8 * i));
          if (s.any) return uint32_t(__builtin_popcount(bvh.occluded8(&rays[8 * i], n)));
          Hit h[8];
          bvh.closest8(&rays[8 * i], n, h, IntersectMethod::Watertight, s.kind);
          uint32_t acc = 0;
          for (int k = 0; k < n; ++k) acc += h[k].prim;
          return acc;
        };
        if (!o.singlesOnly) ours8 = std::min(ours8, timed((rays.size() + 7) / 8, th, 2, packets8));
        for (size_t k = 0; k < o.aloneSweep.size() && !o.singlesOnly; ++k) {  // this set's hand-off threshold set to each value
          int a[3] = {o.aloneRays[0], o.aloneRays[1], o.aloneRays[2]};
          a[s.any ? 2 : int(s.kind)] = o.aloneSweep[k];
          Bvh::setPacketAloneRays(a[0], a[1], a[2]);
          sweep[k] = std::min(sweep[k], timed((rays.size() + 7) / 8, th, 2, packets8));
          Bvh::setPacketAloneRays(o.aloneRays[0], o.aloneRays[1], o.aloneRays[2]);
        }
        Bvh::setPacketLeafRays(9);  // every leaf ray by ray (lanes = triangles), as before round 8
        if (!o.packetsOnly && !o.singlesOnly) ours8r = std::min(ours8r, timed((rays.size() + 7) / 8, th, 2, packets8));
        Bvh::setPacketLeafRays(leafRays);
        if (!o.packetsOnly)
          theirs = std::min(theirs, timed(rays.size(), th, 2, [&](size_t i) {
                              return s.any ? uint32_t(em.occluded(rays[i])) : em.closest(rays[i]).prim;
                            }));
        if (packets && !o.singlesOnly)
          theirs8 = std::min(theirs8, timed((rays.size() + 7) / 8, th, 2, [&](size_t i) {
                               const int n = int(std::min<size_t>(8, rays.size() - 8 * i));
                               return s.any ? em.occluded8(&rays[8 * i], n) : em.closest8(&rays[8 * i], n);
                             }));
      }
      char t8[32] = "–", r8[32] = "–";  // "–": not timed (--singles-only)
      if (!packets) std::snprintf(t8, sizeof t8, "not built in");
      if (packets && theirs8 < 1e30) {
        std::snprintf(t8, sizeof t8, "%.2f", rays.size() / theirs8 * 1e-6);
        std::snprintf(r8, sizeof r8, "%.2f×", theirs8 / ours8);
      }
      // Mrays/s and ratios; "–" where not timed (--packets-only).
      auto fmt = [](double num, double t, const char* f) {
        char b[32] = "–";
        if (t < 1e30) std::snprintf(b, sizeof b, f, num / t);
        return std::string(b);
      };
      const double n = double(rays.size()) * 1e-6;
      std::printf("| %s | %u | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", s.name, th, fmt(n, single, "%.2f").c_str(),
                  fmt(n, paired, "%.2f").c_str(), fmt(n, ours8r, "%.2f").c_str(), fmt(n, ours8, "%.2f").c_str(),
                  fmt(n, theirs, "%.2f").c_str(), t8, fmt(theirs, single, "%.2f×").c_str(), fmt(theirs, paired, "%.2f×").c_str(),
                  r8);
      // Our packets / Embree's packets at each threshold of the sweep, timed in the same turns.
      if (!sweep.empty()) {
        char b[96];
        std::snprintf(b, sizeof b, "\n- %s, %u threads:", s.name, th);
        sweepLines += b;
        for (size_t k = 0; k < sweep.size(); ++k) {
          std::snprintf(b, sizeof b, " from %d live %.2f×", o.aloneSweep[k], theirs8 / sweep[k]);
          sweepLines += b;
        }
      }
    }
  }
  if (!sweepLines.empty())
    std::printf("\nOur packets / Embree's packets, single rays from this many live rays (--alone-sweep):%s\n",
                sweepLines.c_str());
}

// --profile: where a packet's time goes, ours and Embree's, each kind of rays, 1 and N threads. Per
// packet (thread time: wall time × threads / packets): its first pass as timed above; the same packet
// again at once (each packet traced twice in a row, minus one pass: its nodes and triangles in the
// caches, its branches just seen), so first pass − again = what first touching its data costs; and the
// fixed cost of a call (primary rays turned round: they miss the root). With the counted passes a
// packet (box tests and triangle tests, 8-wide, printCounters' columns) the in-cache time a pass.
void printProfile(const Bvh& bvh, const Embree& em, const Rays& all, const Options& o) {
  if (!em.packets()) return;
  std::vector<unsigned> counts{1};
  if (o.threads > 1) counts.push_back(o.threads);
  std::vector<Ray> away = all.primary;
  for (Ray& r : away) r.direction = -r.direction;
  std::printf(
      "\nWhere a packet's time goes (--profile; ns of thread time a packet of 8: first pass, the same packet again at once "
      "with its data in the caches, and their difference, the first touch of its nodes and triangles):\n\n"
      "| rays | threads | ours: ns a packet | again at once | first touch | Embree: ns a packet | again at once | first touch "
      "| our passes a packet: box / triangle | ours again at once, less a call's: ns a pass |\n|---|---|---|---|---|---|---|---|---|---|\n");
  std::vector<RaySet> sets = all.sets();
  sets.insert(sets.begin(), RaySet{"turned round (miss the root: a call's fixed cost)", &away, false, PacketKind::Coherent});
  std::vector<double> box(sets.size()), tri(sets.size());  // passes a packet, counted once a set
  for (unsigned th : counts) {
    double fixedAgain = 0.0;  // ours, a packet that misses the root, again at once
    for (size_t k = 0; k < sets.size(); ++k) {
      const RaySet& s = sets[k];
      const std::vector<Ray>& rays = *s.rays;
      const size_t packets = (rays.size() + 7) / 8;
      auto ours = [&](size_t i) {
        const int n = int(std::min<size_t>(8, rays.size() - 8 * i));
        if (s.any) return uint32_t(bvh.occluded8(&rays[8 * i], n));
        Hit h[8];
        bvh.closest8(&rays[8 * i], n, h, IntersectMethod::Watertight, s.kind);
        return h[0].prim + h[n - 1].prim;
      };
      auto theirs = [&](size_t i) {
        const int n = int(std::min<size_t>(8, rays.size() - 8 * i));
        return s.any ? em.occluded8(&rays[8 * i], n) : em.closest8(&rays[8 * i], n);
      };
      double t[4] = {1e30, 1e30, 1e30, 1e30};  // ours once, twice; Embree once, twice
      for (int r = 0; r < o.reps; ++r) {
        t[0] = std::min(t[0], timed(packets, th, 2, ours));
        t[1] = std::min(t[1], timed(packets, th, 2, [&](size_t i) { return ours(i) + ours(i); }));
        t[2] = std::min(t[2], timed(packets, th, 2, theirs));
        t[3] = std::min(t[3], timed(packets, th, 2, [&](size_t i) { return theirs(i) + theirs(i); }));
      }
      const double ns = 1e9 * double(th) / double(packets);
      const double oursOnce = t[0] * ns, oursAgain = (t[1] - t[0]) * ns, emOnce = t[2] * ns, emAgain = (t[3] - t[2]) * ns;
      if (th == counts[0]) {  // passes a packet, counted (one thread, the counting traversal: the same decisions)
        Bvh::setCounting(true);
        Bvh::counters() = {};
        for (size_t i = 0; i < packets; ++i) ours(i);
        const BvhCounters c = Bvh::counters();
        Bvh::counters() = {};
        Bvh::setCounting(false);
        box[k] = double(c.intervalTests + c.childTests + c.nodes) / double(packets);
        tri[k] = double(c.triangleTests + c.packs) / double(packets);
      }
      char perPass[32] = "–";
      if (s.rays == &away) fixedAgain = oursAgain;
      else std::snprintf(perPass, sizeof perPass, "%.1f", (oursAgain - fixedAgain) / std::max(1e-9, box[k] + tri[k]));
      std::printf("| %s | %u | %.0f | %.0f | %.0f (%.0f %%) | %.0f | %.0f | %.0f (%.0f %%) | %.1f / %.1f | %s |\n", s.name, th,
                  oursOnce, oursAgain, oursOnce - oursAgain, 100.0 * (oursOnce - oursAgain) / oursOnce, emOnce, emAgain,
                  emOnce - emAgain, 100.0 * (emOnce - emAgain) / emOnce, box[k], tri[k], perPass);
    }
  }
}

// Primary rays through our BVH with each intersection routine, one thread.
void printRoutines(const Bvh& bvh, const std::vector<Ray>& primary) {
  std::printf("\nPrimary rays through our BVH with the other routines (1 thread):\n\n| routine | Mrays/s |\n|---|---|\n");
  for (IntersectMethod m : {IntersectMethod::Watertight, IntersectMethod::MollerTrumbore, IntersectMethod::HalfPlane}) {
    const double t = timed(primary.size(), 1, 2, [&](size_t i) { return bvh.closest(primary[i], m).prim; });
    std::printf("| %s | %.2f |\n",
                m == IntersectMethod::Watertight  ? "watertight (8-wide)"
                : m == IntersectMethod::HalfPlane ? "half-plane (scalar)"
                                                  : "Möller–Trumbore (scalar)",
                primary.size() / t * 1e-6);
  }
}

void benchScene(const char* label, const std::vector<Triangle>& tris, const Bounds& bounds, bool sphere, const Options& o) {
  std::printf("\n## %s: %zu triangles, %ux%u primary rays, %u threads max, our traversal: %s\n\n", label, tris.size(), o.res,
              o.res, o.threads, Bvh::isaName(Bvh::isa()));
  if (o.buildOnly) return benchBuilds(tris, o);
  const auto t0 = Clock::now();
  const Bvh bvh(tris, {}, o.threads);
  const double ourBuild = seconds(t0);
  const Embree em(tris, o.threads);
  printBuilds(tris, bvh, ourBuild, em, o.threads);
  const Rays rays = makeRays(tris, bounds, sphere, bvh, o.res, o.mirrorTiles);
  if (!o.packetsOnly && !o.singlesOnly) printAgreement(tris, bvh, em, rays, o.explainAll);
  printPacketAgreement(bvh, em, rays, o.leafRays);
  if (!o.packetsOnly && !o.singlesOnly) printCounters(bvh, rays.sets());
  if (o.countOnly) {  // and the same with every leaf tested ray by ray
    std::printf("\nThe same, every leaf of a packet tested ray by ray (--leaf-rays 9):\n");
    Bvh::setPacketLeafRays(9);
    printCounters(bvh, rays.sets());
    Bvh::setPacketLeafRays(o.leafRays);
    return;
  }
  printSpeeds(bvh, em, rays, o);
  if (o.profile) printProfile(bvh, em, rays, o);
  if (!o.quick) printRoutines(bvh, rays.primary);
}

// Single ray/triangle tests in a tight loop (scalar), and each routine's miss rate on a closed sphere seen
// from inside (100k random rays + rays at every vertex and along every edge).
void benchRoutines() {
  std::printf("\n## Ray/triangle routines alone (scalar, 1 thread)\n\n");
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Triangle> tris(4096);
  std::vector<Ray> rays(4096);
  for (auto& t : tris) t = {{u(rng), u(rng), -2 + u(rng)}, {u(rng), u(rng), -2 + u(rng)}, {u(rng), u(rng), -2 + u(rng)}};
  for (auto& r : rays) r = {{u(rng) * 0.1f, u(rng) * 0.1f, 0}, {u(rng) * 0.5f, u(rng) * 0.5f, -1}};
  const Mesh sphere = uvSphere({0.3f, -0.2f, 0.1f}, 3.7f, 16, 16);
  std::vector<Triangle> st;
  for (size_t i = 0; i < sphere.indices.size(); i += 3)
    st.push_back(
        {sphere.positions[sphere.indices[i]], sphere.positions[sphere.indices[i + 1]], sphere.positions[sphere.indices[i + 2]]});
  std::vector<Ray> inside;
  auto in = [&] {
    glm::vec3 p;
    do p = {u(rng), u(rng), u(rng)};
    while (glm::length(p) > 0.8f);
    return glm::vec3(0.3f, -0.2f, 0.1f) + p * 2.5f;
  };
  for (int i = 0; i < 100000; ++i) inside.push_back({in(), {u(rng), u(rng), u(rng)}});
  for (const glm::vec3& v : sphere.positions) {
    const glm::vec3 o = in();
    inside.push_back({o, v - o});
  }
  for (size_t i = 0; i < sphere.indices.size(); i += 3)
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 a = sphere.positions[sphere.indices[i + k]], b = sphere.positions[sphere.indices[i + (k + 1) % 3]];
      const glm::vec3 o = in();
      inside.push_back({o, a + 0.5f * (b - a) - o});
    }
  const Bvh sb(st);
  std::printf("| routine | M tests/s | closed-sphere misses (of %zu rays) |\n|---|---|---|\n", inside.size());
  float sink = 0;
  for (IntersectMethod m : {IntersectMethod::HalfPlane, IntersectMethod::MollerTrumbore, IntersectMethod::Watertight}) {
    const auto start = Clock::now();
    float acc = 0;
    for (int rep = 0; rep < 8; ++rep)
      for (size_t i = 0; i < rays.size(); ++i)
        for (int j = 0; j < 16; ++j) {
          float b1, b2;
          acc += intersect(m, rays[i], tris[(i * 16 + j + rep) & 4095], b1, b2);
        }
    const double t = seconds(start);
    sink += acc;
    size_t misses = 0;
    for (const Ray& r : inside) misses += !sb.closest(r, m).hit();
    std::printf("| %s | %.1f | %zu (%.3f %%) |\n",
                m == IntersectMethod::Watertight  ? "watertight"
                : m == IntersectMethod::HalfPlane ? "half-plane"
                                                  : "Möller–Trumbore",
                8.0 * rays.size() * 16 / t * 1e-6, misses, 100.0 * double(misses) / double(inside.size()));
  }
  if (sink == 12345.0f) std::printf(" ");  // keeps the timed loops from being optimised away
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  unsigned& threads = o.threads;
  int &res = o.res, &reps = o.reps, &leafRays = o.leafRays;
  bool &quick = o.quick, &explainAll = o.explainAll, &countOnly = o.countOnly;
  uint32_t rings = 707;
  bool noSphere = false, badGrain = false;
  std::vector<std::string> scenes;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--threads" && i + 1 < argc) threads = unsigned(std::atoi(argv[++i]));
    else if (a == "--res" && i + 1 < argc) res = std::atoi(argv[++i]);
    else if (a == "--rings" && i + 1 < argc) rings = uint32_t(std::atoi(argv[++i]));
    else if (a == "--scene" && i + 1 < argc) scenes.push_back(argv[++i]);
    else if (a == "--reps" && i + 1 < argc) reps = std::atoi(argv[++i]);
    else if (a == "--leaf-rays" && i + 1 < argc) leafRays = std::atoi(argv[++i]);
    else if (a == "--alone-rays" && i + 1 < argc) {
      if (std::sscanf(argv[++i], "%d,%d,%d", &o.aloneRays[0], &o.aloneRays[1], &o.aloneRays[2]) != 3) o.aloneRays[0] = -1;
    } else if (a == "--alone-sweep" && i + 1 < argc) {
      for (const char* p = argv[++i]; *p; ++p)
        if (p == argv[i] || p[-1] == ',') o.aloneSweep.push_back(std::atoi(p));
    } else if (a == "--mirror-tiles" && i + 1 < argc) {
      for (const char* p = argv[++i]; *p; ++p)
        if (p == argv[i] || p[-1] == ',') o.mirrorTiles.push_back(std::max(1, std::atoi(p)));
    } else if (a == "--build-grain" && i + 1 < argc) {
      for (const char* p = argv[++i]; *p; ++p)
        if (p == argv[i] || p[-1] == ',') {
          unsigned t = 0, c = 0;
          if (std::sscanf(p, "%u/%u", &t, &c) != 2 || t == 0 || c == 0) badGrain = true;
          o.grains.push_back({t, c});
        }
    } else if (a == "--quick") quick = true;
    else if (a == "--count-only") quick = countOnly = true;
    else if (a == "--packets-only") quick = o.packetsOnly = true;
    else if (a == "--singles-only") quick = o.singlesOnly = true;
    else if (a == "--no-sphere") noSphere = true;
    else if (a == "--build-only") quick = o.buildOnly = true;
    else if (a == "--explain") explainAll = true;
    else if (a == "--cpu-time") gCpuTime = true;
    else if (a == "--profile") o.profile = true;
    else if (a == "--sse") Bvh::setIsa(BvhIsa::Sse);
    else if (a == "--avx2") Bvh::setIsa(BvhIsa::Avx2);
    else {
      std::fprintf(
          stderr,
          "usage: bench-trace [--threads N] [--res N] [--rings N] [--scene FILE]... [--quick] [--reps N] [--sse|--avx2] [--explain] [--leaf-rays N] [--alone-rays C,S,A] [--alone-sweep N,...] [--count-only] [--packets-only] [--singles-only] [--build-only] [--no-sphere] [--cpu-time] [--profile] [--mirror-tiles N,...] [--build-grain T/C,...]\n"
          "  --quick: only the tracers' table (no routine timings, no other routines through the BVH)\n"
          "  --reps N: time ours and Embree alternately N times, keep the best of each (default 3)\n"
          "  --sse, --avx2: our traversal with SSE4.2 or AVX2 even where a wider ISA is available\n"
          "  --explain: one line per hit/miss disagreement with Embree\n"
          "  --count-only: builds, agreement and work per ray (counted), no timing\n"
          "  --leaf-rays N: our packets test a leaf all rays at once from N live rays (9: never)\n"
          "  --alone-rays C,S,A: our packets walk on as single rays from this many live rays or fewer: closest hit\n"
          "    coherent (primary, orthographic), closest hit scattered (mirror), any hit (shadow)\n"
          "  --alone-sweep N,...: our packets also timed with each set's threshold at each N (same turns)\n"
          "  --packets-only: time only ours and Embree's packets (quick A/B runs; implies --quick)\n"
          "  --singles-only: time only our single rays and pairs and Embree's single rays (the same; implies --quick)\n"
          "  --build-only: only our and Embree's BVH builds, --reps times alternately, phases and tree hash\n"
          "  --no-sphere: only the --scene files\n"
          "  --profile: where our and Embree's packets spend their time (first pass, again in cache, set-up)\n"
          "  --cpu-time: time by the threads' CPU time, not the wall clock (A/B runs on a shared machine)\n"
          "  --mirror-tiles N,...: also the mirror rays regrouped per tile of N × N pixels: in Z-order, by octant, by\n"
          "    octant and major axis (counted and timed as rows of their own, ours and Embree's)\n"
          "  --build-grain T/C,...: with --build-only, our build also timed with subtree tasks from T triangles and\n"
          "    chunks of C references (Bvh::setBuildGrain; the same tree)\n");
      return 2;
    }
  }
  bool badAlone = false;
  for (int n : o.aloneRays) badAlone |= n < 0 || n > 8;
  for (int n : o.aloneSweep) badAlone |= n < 0 || n > 8;
  if (threads == 0 || res <= 0 || rings < 2 || reps < 1 || badAlone || badGrain) {
    std::fprintf(stderr, "bench-trace: bad argument\n");
    return 2;
  }
  Bvh::setPacketLeafRays(leafRays);
  Bvh::setPacketAloneRays(o.aloneRays[0], o.aloneRays[1], o.aloneRays[2]);
  if (!quick) benchRoutines();
  const Mesh sphere = uvSphere({0, 0, 0}, 1.0f, rings, rings + 1);
  std::vector<Triangle> tris;
  for (size_t i = 0; i < sphere.indices.size(); i += 3)
    tris.push_back(
        {sphere.positions[sphere.indices[i]], sphere.positions[sphere.indices[i + 1]], sphere.positions[sphere.indices[i + 2]]});
  if (!noSphere) benchScene("UV sphere", tris, sphere.bounds, true, o);
  for (const std::string& f : scenes) {
    try {
      const Scene s = loadScene(f);
      benchScene(f.c_str(), trianglesOf(s), s.bounds(), false, o);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench-trace: %s\n", e.what());
      return 1;
    }
  }
  return 0;
}
