// rtr-lod-cut: the level-of-detail cut that rtr-view's culling pass would choose (docs/virtual-geometry.md),
// computed on the CPU with the same rule (shaders/shared/cluster_lod.h) and the same projection (the eye,
// pixels per unit = image height / (2 tan(fovY / 2)), the near plane of the view's fitted depth range), and
// where it comes from: per level of the hierarchy its clusters, triangles, roots and errors, and per
// threshold the clusters and triangles the cut takes from each level, how many lie in the view frustum and
// how large their triangles are on screen. --rebuild builds the hierarchy again (the build's per-group
// record: how far each level's groups simplified, which groups stuck, which error term decided). No GPU.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "cluster_lod.h"
#include "core/cli.hpp"
#include "cull.h"
#include "raster.h"
#include "scene/cluster_lod.hpp"
#include "scene/clusters.hpp"
#include "scene/framing.hpp"
#include "scene/load.hpp"

using namespace rtr;

namespace {

float median(std::vector<float> v) {
  if (v.empty()) return 0.0f;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Per level of the build: groups, how they simplified, which term of the error decided.
void printBuild(const std::vector<LodGroupStats>& stats) {
  std::map<uint32_t, std::vector<const LodGroupStats*>> byLevel;
  for (const LodGroupStats& s : stats) byLevel[s.level].push_back(&s);
  std::printf(
      "\nbuild, per level grouped (the groups' result is the next level):\n"
      "| level | groups | alone | stuck (tris) | welded | tris in → out | out / in | size term decides | simplifier error "
      "median | size term median | size term / group radius median |\n|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|\n");
  for (const auto& [level, groups] : byLevel) {
    size_t alone = 0, stuck = 0, stuckTris = 0, welded = 0, in = 0, out = 0, sizeDecides = 0, simplified = 0;
    std::vector<float> simp, edge, edgeRel;
    for (const LodGroupStats* g : groups) {
      if (g->clusters < 2) ++alone, stuckTris += g->trianglesIn;
      else if (g->trianglesOut == 0) ++stuck, stuckTris += g->trianglesIn;
      if (g->trianglesOut == 0) continue;
      ++simplified, welded += g->welded;
      in += g->trianglesIn, out += g->trianglesOut;
      sizeDecides += g->edgeError > g->simplifierError;
      simp.push_back(g->simplifierError), edge.push_back(g->edgeError);
      edgeRel.push_back(g->radius > 0 ? g->edgeError / g->radius : 0.0f);
    }
    std::printf("| %u | %zu | %zu | %zu (%zu) | %zu | %zu → %zu | %.3f | %.1f %% | %.3g | %.3g | %.3f |\n", level, groups.size(),
                alone, stuck, stuckTris, welded, in, out, in ? double(out) / double(in) : 0.0,
                simplified ? 100.0 * double(sizeDecides) / double(simplified) : 0.0, median(simp), median(edge), median(edgeRel));
  }
}

struct View {
  glm::vec3 eye;
  glm::mat4 viewProj;
  float pixelsPerUnit, zNear;
  uint32_t width, height;
};

// The hierarchy per level, all meshes together.
void printLevels(const Scene& scene) {
  struct Row {
    size_t clusters = 0, triangles = 0, roots = 0, rootTriangles = 0;
    std::vector<float> errors, radii, groupRadii, fill;
  };
  std::map<uint32_t, Row> rows;
  for (const Mesh& m : scene.meshes)
    for (const LodCluster& c : m.lod.clusters) {
      Row& r = rows[c.level];
      ++r.clusters, r.triangles += c.triangleCount, r.errors.push_back(c.error);
      r.radii.push_back(c.radius), r.groupRadii.push_back(c.sphere.w);
      // How much of its sphere's disc its triangles cover: ~1 for a round flat patch, small for a strip.
      double area = 0.0;
      const std::span<const uint32_t> t = lodTriangles(m, c);
      for (size_t k = 0; k < t.size(); k += 3)
        area +=
            0.5 * glm::length(glm::cross(m.positions[t[k + 1]] - m.positions[t[k]], m.positions[t[k + 2]] - m.positions[t[k]]));
      r.fill.push_back(c.radius > 0 ? float(area / (3.14159265 * c.radius * c.radius)) : 0.0f);
      if (c.parentError >= shader::LOD_ERROR_INFINITE) ++r.roots, r.rootTriangles += c.triangleCount;
    }
  std::printf(
      "\nhierarchy, per level (all meshes):\n| level | clusters | triangles | tris / cluster | roots (their tris) | error min / "
      "median / max | radius median: cluster, group | area / disc median |\n|---:|---:|---:|---:|---:|---|---|---:|\n");
  for (auto& [level, r] : rows) {
    const auto [lo, hi] = std::minmax_element(r.errors.begin(), r.errors.end());
    std::printf("| %u | %zu | %zu | %.1f | %zu (%zu) | %.3g / %.3g / %.3g | %.3g, %.3g | %.2f |\n", level, r.clusters,
                r.triangles, double(r.triangles) / double(r.clusters), r.roots, r.rootTriangles, *lo, median(r.errors), *hi,
                median(r.radii), median(r.groupRadii), median(r.fill));
  }
}

// The cut at `threshold` pixels, per level: as rtr-view's culling pass with --cull off lists it (every
// instance's clusters; a mesh without a hierarchy whole), and of it what lies in the view frustum with
// its triangles' area on screen.
void printCut(const Scene& scene, const View& v, float threshold) {
  struct Row {
    size_t clusters = 0, triangles = 0, roots = 0, inClusters = 0, inTriangles = 0, large = 0, tiles = 0;
    double area = 0.0;
    std::array<size_t, 6> areaBins{};  // < 1/4, < 1, < 4, < 16, < 64, >= 64 px
  };
  std::map<uint32_t, Row> rows;
  std::vector<std::array<size_t, 4>> perMesh(scene.meshes.size());  // triangles in the cut, of level 0, in the frustum, roots
  std::vector<Instance> instances = scene.instances;
  if (instances.empty())
    for (uint32_t m = 0; m < scene.meshes.size(); ++m) instances.push_back({m, glm::mat4(1.0f)});
  for (const Instance& inst : instances) {
    const Mesh& m = scene.meshes[inst.mesh];
    // Spheres and errors in scene space as render/cull.cpp places them (centre by the matrix, radius and
    // error by the largest stretch).
    const float stretch = std::sqrt(std::max({glm::dot(glm::vec3(inst.transform[0]), glm::vec3(inst.transform[0])),
                                              glm::dot(glm::vec3(inst.transform[1]), glm::vec3(inst.transform[1])),
                                              glm::dot(glm::vec3(inst.transform[2]), glm::vec3(inst.transform[2]))}));
    auto place = [&](glm::vec4 s) { return glm::vec4(glm::vec3(inst.transform * glm::vec4(glm::vec3(s), 1.0f)), s.w * stretch); };
    auto scaled = [&](float e) { return e >= shader::LOD_ERROR_INFINITE ? e : e * stretch; };
    std::vector<LodCluster> whole;
    if (m.lod.clusters.empty())
      for (const Cluster& c : m.clusters) {
        LodCluster l;
        l.firstTriangle = c.firstTriangle, l.triangleCount = c.triangleCount, l.center = c.center, l.radius = c.radius;
        l.sphere = l.parentSphere = glm::vec4(c.center, c.radius);
        l.parentError = shader::LOD_ERROR_INFINITE;
        whole.push_back(l);
      }
    for (const LodCluster& c : m.lod.clusters.empty() ? whole : m.lod.clusters) {
      if (!shader::lodSelected(place(c.sphere), scaled(c.error), place(c.parentSphere), scaled(c.parentError), v.eye,
                               v.pixelsPerUnit, v.zNear, threshold))
        continue;
      Row& r = rows[c.level];
      ++r.clusters, r.triangles += c.triangleCount;
      perMesh[inst.mesh][0] += c.triangleCount, perMesh[inst.mesh][1] += c.level == 0 ? c.triangleCount : 0;
      r.roots += c.parentError >= shader::LOD_ERROR_INFINITE;
      perMesh[inst.mesh][3] += c.parentError >= shader::LOD_ERROR_INFINITE ? c.triangleCount : 0;
      if (shader::frustumCulls(place(glm::vec4(c.center, c.radius)), v.viewProj)) continue;
      ++r.inClusters, r.inTriangles += c.triangleCount, perMesh[inst.mesh][2] += c.triangleCount;
      const glm::mat4 toClip = v.viewProj * inst.transform;
      const std::span<const uint32_t> tris = lodTriangles(m, c);
      for (size_t t = 0; t < tris.size(); t += 3) {
        glm::vec2 p[3];
        bool behind = false;
        for (int k = 0; k < 3; ++k) {
          const glm::vec4 h = toClip * glm::vec4(m.positions[tris[t + k]], 1.0f);
          behind |= h.w <= 0.0f;
          p[k] = glm::vec2(h) / h.w * 0.5f * glm::vec2(v.width, v.height);
        }
        if (behind) continue;  // crosses the camera plane: the hardware hand-off's
        const float area = 0.5f * std::abs((p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y));
        const glm::vec2 lo = glm::min(p[0], glm::min(p[1], p[2])), hi = glm::max(p[0], glm::max(p[1], p[2]));
        // About RASTER_SHARED_AREA's rule (the box on screen): the tile pass, one entry per 32 × 32 tile.
        const glm::vec2 half = 0.5f * glm::vec2(v.width, v.height);
        const glm::vec2 a = glm::clamp(lo, -half, half), b = glm::clamp(hi, -half, half);
        if ((b.x - a.x) * (b.y - a.y) > 256.0f)
          ++r.large, r.tiles += size_t(std::ceil((b.x - a.x) / 32.0f) * std::ceil((b.y - a.y) / 32.0f));
        r.area += area;
        ++r.areaBins[area < 0.25f ? 0 : area < 1 ? 1 : area < 4 ? 2 : area < 16 ? 3 : area < 64 ? 4 : 5];
      }
    }
  }
  std::printf(
      "\ncut at %g px: | level | clusters | triangles | of them roots (clusters) | in the frustum: clusters | triangles | "
      "mean area px | area < 1/4, < 1, < 4, < 16, < 64, more (%% of tris) | box > 256 px (32-px tiles) |\n"
      "|---:|---:|---:|---:|---:|---:|---:|---|---:|\n",
      threshold);
  Row all;
  for (auto& [level, r] : rows) {
    const size_t n = std::max<size_t>(1, r.inTriangles);
    std::printf("| %u | %zu | %zu | %zu | %zu | %zu | %.2f | %.0f / %.0f / %.0f / %.0f / %.0f / %.0f | %zu (%zu) |\n", level,
                r.clusters, r.triangles, r.roots, r.inClusters, r.inTriangles, r.area / double(n), 100.0 * r.areaBins[0] / n,
                100.0 * r.areaBins[1] / n, 100.0 * r.areaBins[2] / n, 100.0 * r.areaBins[3] / n, 100.0 * r.areaBins[4] / n,
                100.0 * r.areaBins[5] / n, r.large, r.tiles);
    all.clusters += r.clusters, all.triangles += r.triangles, all.roots += r.roots, all.inClusters += r.inClusters;
    all.inTriangles += r.inTriangles, all.area += r.area, all.large += r.large, all.tiles += r.tiles;
  }
  std::printf("per mesh (triangles: mesh → cut, of them level 0, in the frustum, of roots):");
  for (size_t m = 0; m < scene.meshes.size(); ++m)
    std::printf(" %s %u → %zu, %zu, %zu, %zu;", scene.meshes[m].name.c_str(), scene.meshes[m].triangleCount(), perMesh[m][0],
                perMesh[m][1], perMesh[m][2], perMesh[m][3]);
  std::printf("\n");
  const double pixels = double(v.width) * v.height;
  std::printf("| all | %zu | %zu | %zu | %zu | %zu | %.2f | | %zu (%zu) |\n", all.clusters, all.triangles, all.roots,
              all.inClusters, all.inTriangles, all.area / double(std::max<size_t>(1, all.inTriangles)), all.large, all.tiles);
  std::printf(
      "cut at %g px: %zu triangles listed (%.2f a pixel), %zu in the frustum (%.2f a pixel), %zu clusters listed, %zu tiles of "
      "%zu large triangles\n",
      threshold, all.triangles, all.triangles / pixels, all.inTriangles, all.inTriangles / pixels, all.clusters, all.tiles,
      all.large);
}

// What becomes of the triangles the culling pass lists at this view (the cut, clusters in the frustum and
// not back-facing by their cone; as with --cull off, so no cluster is occluded), on the compute
// rasteriser's rules (shaders/render/raster_tri.glsl, in floating point): none of the view volume, handed
// to the hardware (crossing the camera plane), zero area, back-facing, no pixel centre in its box, centres
// in its box but none inside, every sample it covers won by a nearer triangle (a depth buffer of all of
// them), or drawn (wins a pixel). Per cluster: the triangles of clusters that draw nothing at all.
void printFates(const Scene& scene, const View& v, float threshold) {
  enum Fate { Outside, HandOff, Degenerate, Back, NoCentre, NoSample, Hidden, Drawn, kFates };
  static const char* kNames[kFates] = {"outside the view", "hand-off",         "zero area",      "back-facing",
                                       "no centre in box", "no sample inside", "hidden (depth)", "drawn"};
  struct Tri {
    glm::vec2 p[3];  // pixels, ordered so that the edge functions are positive inside
    glm::vec3 z;
    glm::ivec4 box;
    uint32_t fate;  // its index in `fates`
  };
  std::vector<Tri> tris;
  std::vector<uint8_t> fates;      // per listed triangle
  std::vector<uint32_t> firstOf;   // per listed cluster: its first triangle in `fates`
  std::vector<glm::vec4> spheres;  // per listed cluster: its culling sphere, placed
  std::vector<Instance> instances = scene.instances;
  if (instances.empty())
    for (uint32_t m = 0; m < scene.meshes.size(); ++m) instances.push_back({m, glm::mat4(1.0f)});
  const glm::vec2 size(v.width, v.height);
  for (const Instance& inst : instances) {
    const Mesh& m = scene.meshes[inst.mesh];
    const Material& mat = scene.materials.at(m.material);
    if (mat.blended()) continue;  // the transparency pass's
    const glm::mat3 l(inst.transform);
    const float stretch = std::max({glm::length(l[0]), glm::length(l[1]), glm::length(l[2])});
    const bool similar = std::abs(glm::length(l[0]) - stretch) < 1e-5f * stretch &&
                         std::abs(glm::length(l[1]) - stretch) < 1e-5f * stretch &&
                         std::abs(glm::dot(l[0], l[1])) + std::abs(glm::dot(l[0], l[2])) + std::abs(glm::dot(l[1], l[2])) <
                             1e-5f * stretch * stretch;
    const bool twoSided = !conesCull(mat), mirror = glm::determinant(l) < 0.0f;
    auto place = [&](glm::vec4 s) { return glm::vec4(glm::vec3(inst.transform * glm::vec4(glm::vec3(s), 1.0f)), s.w * stretch); };
    auto scaled = [&](float e) { return e >= shader::LOD_ERROR_INFINITE ? e : e * stretch; };
    std::vector<LodCluster> whole;
    if (m.lod.clusters.empty())
      for (const Cluster& c : m.clusters) {
        LodCluster lc;
        lc.firstTriangle = c.firstTriangle, lc.triangleCount = c.triangleCount, lc.center = c.center, lc.radius = c.radius;
        lc.coneAxis = c.coneAxis, lc.coneCutoff = c.coneCutoff;
        lc.sphere = lc.parentSphere = glm::vec4(c.center, c.radius);
        lc.parentError = shader::LOD_ERROR_INFINITE;
        whole.push_back(lc);
      }
    const glm::mat4 toClip = v.viewProj * inst.transform;
    for (const LodCluster& c : m.lod.clusters.empty() ? whole : m.lod.clusters) {
      if (!shader::lodSelected(place(c.sphere), scaled(c.error), place(c.parentSphere), scaled(c.parentError), v.eye,
                               v.pixelsPerUnit, v.zNear, threshold))
        continue;
      const glm::vec4 sphere = place(glm::vec4(c.center, c.radius));
      if (shader::frustumCulls(sphere, v.viewProj)) continue;
      const glm::vec4 cone = twoSided || !similar || c.coneCutoff >= 1.0f
                                 ? glm::vec4(0, 0, 1, 2)
                                 : glm::vec4(glm::normalize(l * c.coneAxis), c.coneCutoff);
      if (shader::coneCulls(sphere, cone, v.eye)) continue;
      firstOf.push_back(uint32_t(fates.size())), spheres.push_back(sphere);
      const std::span<const uint32_t> idx = lodTriangles(m, c);
      for (size_t t = 0; t < idx.size(); t += 3) {
        glm::vec4 h[3];
        for (int k = 0; k < 3; ++k) h[k] = toClip * glm::vec4(m.positions[idx[t + k]], 1.0f);
        Fate f = Drawn;
        for (int k = 0; k < 3 && f == Drawn; ++k)
          if ((h[0][k] > h[0].w && h[1][k] > h[1].w && h[2][k] > h[2].w) ||
              (k < 2 && h[0][k] < -h[0].w && h[1][k] < -h[1].w && h[2][k] < -h[2].w) || (h[0].z < 0 && h[1].z < 0 && h[2].z < 0))
            f = Outside;
        if (f == Drawn && std::min({h[0].w, h[1].w, h[2].w}) <= 0.0f) f = HandOff;
        Tri tri{};
        for (int k = 0; k < 3 && f == Drawn; ++k) {
          tri.p[k] = (glm::vec2(h[k]) / h[k].w * 0.5f + 0.5f) * size;
          tri.z[k] = h[k].z / h[k].w;
          if (glm::any(glm::greaterThan(glm::abs(tri.p[k] - 0.5f * size), glm::vec2(RASTER_GUARD_BAND)))) f = HandOff;
        }
        if (f == Drawn) {
          // Counter-clockwise in framebuffer coordinates (y down) is front: a negative area here.
          const float area2 =
              (tri.p[1].x - tri.p[0].x) * (tri.p[2].y - tri.p[0].y) - (tri.p[1].y - tri.p[0].y) * (tri.p[2].x - tri.p[0].x);
          if (area2 == 0.0f) f = Degenerate;
          else if ((area2 > 0.0f) != mirror && !twoSided) f = Back;
          else if (area2 < 0.0f) std::swap(tri.p[1], tri.p[2]), std::swap(tri.z[1], tri.z[2]);
        }
        if (f == Drawn) {
          const glm::vec2 lo = glm::min(tri.p[0], glm::min(tri.p[1], tri.p[2])),
                          hi = glm::max(tri.p[0], glm::max(tri.p[1], tri.p[2]));
          tri.box = glm::ivec4(std::max(0, int(std::ceil(lo.x - 0.5f))), std::max(0, int(std::ceil(lo.y - 0.5f))),
                               std::min(int(v.width) - 1, int(std::floor(hi.x - 0.5f))),
                               std::min(int(v.height) - 1, int(std::floor(hi.y - 0.5f))));
          if (tri.box.x > tri.box.z || tri.box.y > tri.box.w) f = NoCentre;
        }
        fates.push_back(uint8_t(f));
        if (f == Drawn) tri.fate = uint32_t(fates.size() - 1), tris.push_back(tri);
      }
    }
  }
  firstOf.push_back(uint32_t(fates.size()));
  // Two passes over the rasterised triangles: the nearest depth per pixel, then which triangles reach it.
  std::vector<float> depth(size_t(v.width) * v.height, 2.0f);
  auto cover = [&](const Tri& t, auto&& at) {
    auto edge = [](glm::vec2 a, glm::vec2 b, glm::vec2 p) { return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x); };
    const float area = edge(t.p[0], t.p[1], t.p[2]);
    for (int y = t.box.y; y <= t.box.w; ++y)
      for (int x = t.box.x; x <= t.box.z; ++x) {
        const glm::vec2 p(x + 0.5f, y + 0.5f);
        const glm::vec3 e(edge(t.p[1], t.p[2], p), edge(t.p[2], t.p[0], p), edge(t.p[0], t.p[1], p));
        if (e.x < 0 || e.y < 0 || e.z < 0) continue;
        at(size_t(y) * v.width + x, glm::dot(e, t.z) / area);
      }
  };
  for (const Tri& t : tris) cover(t, [&](size_t px, float z) { depth[px] = std::min(depth[px], z); });
  for (const Tri& t : tris) {
    bool any = false, wins = false;
    cover(t, [&](size_t px, float z) { any = true, wins |= z <= depth[px]; });
    fates[t.fate] = uint8_t(!any ? NoSample : wins ? Drawn : Hidden);
  }
  // The depth pyramid of that depth (render/cull.cpp's DepthPyramid: farthest of each 2 × 2, level 0 half
  // the image, sizes rounding down, the odd last texel folded in), and the occlusion test of the culling
  // pass on it (shared/cull.h), at the level where a box covers at most span × span texels (2, 4, 8).
  std::vector<std::vector<float>> levels;
  std::vector<glm::ivec2> sizes;
  glm::ivec2 below(v.width, v.height);
  for (glm::ivec2 e = glm::max(below / 2, 1);; e = glm::max(e / 2, 1)) {
    const std::vector<float>& src = levels.empty() ? depth : levels.back();
    std::vector<float> dst(size_t(e.x) * e.y, 0.0f);
    for (int y = 0; y < below.y; ++y)
      for (int x = 0; x < below.x; ++x) {
        float& d = dst[size_t(std::min(y / 2, e.y - 1)) * e.x + std::min(x / 2, e.x - 1)];
        d = std::max(d, std::min(1.0f, src[size_t(y) * below.x + x]));
      }
    levels.push_back(std::move(dst)), sizes.push_back(e), below = e;
    if (e == glm::ivec2(1)) break;
  }
  auto occluded = [&](glm::vec4 sphere, int span) {
    const shader::ProjectedBox b = shader::projectBox(sphere, v.viewProj, v.width, v.height);
    if (b.inFront == 0u) return false;
    const int level = shader::pyramidLevelFor(b.pixels, int(levels.size()), span);
    const glm::ivec4 t = shader::pyramidTexels(b.pixels, level, sizes[level]);
    float farthest = 0.0f;
    for (int y = t.y; y <= t.w; ++y)
      for (int x = t.x; x <= t.z; ++x) farthest = std::max(farthest, levels[level][size_t(y) * sizes[level].x + x]);
    return b.nearestDepth > farthest;
  };
  std::array<size_t, kFates> n{}, kept{};  // all listed; those of the clusters the pass's occlusion test keeps
  size_t idle = 0, idleClusters = 0, allBack = 0, allHidden = 0;
  std::array<size_t, 3> caught{}, caughtTris{}, wrong{};  // by the pyramid: 2 × 2, up to 4 × 4, 8 × 8 texels
  for (size_t c = 0; c + 1 < firstOf.size(); ++c) {
    std::array<size_t, kFates> k{};
    for (uint32_t t = firstOf[c]; t < firstOf[c + 1]; ++t) ++k[fates[t]];
    const size_t count = firstOf[c + 1] - firstOf[c];
    const bool drawsNothing = k[Drawn] + k[HandOff] == 0;
    if (drawsNothing) idle += count, ++idleClusters;
    allBack += k[Back] == count ? count : 0, allHidden += k[Hidden] == count ? count : 0;
    for (int i = 0; i < 3; ++i)
      if (occluded(spheres[c], 2 << i)) ++caught[i], caughtTris[i] += count, wrong[i] += !drawsNothing;
    for (int f = 0; f < kFates; ++f) n[f] += k[f], kept[f] += occluded(spheres[c], CULL_PYRAMID_SPAN) ? 0 : k[f];
  }
  auto print = [&](const char* what, const std::array<size_t, kFates>& c) {
    size_t all = 0;
    for (size_t k : c) all += k;
    std::printf("fates at %g px, %s: %zu triangles;", threshold, what, all);
    for (int f = 0; f < kFates; ++f)
      std::printf(" %s %zu (%.1f %%)%s", kNames[f], c[f], 100.0 * double(c[f]) / double(std::max<size_t>(1, all)),
                  f + 1 < kFates ? "," : "\n");
  };
  print("listed without occlusion", n);
  print("kept by the pyramid of the final depth (a still view's two-phase list)", kept);
  std::printf(
      "fates at %g px: %zu clusters (%zu triangles) draw nothing; of those all back-facing %zu triangles, all hidden %zu\n",
      threshold, idleClusters, idle, allBack, allHidden);
  std::printf("fates at %g px: the pyramid of this depth culls, reading up to 2 × 2 / 4 × 4 / 8 × 8 texels:", threshold);
  for (int i = 0; i < 3; ++i)
    std::printf(" %zu clusters (%zu triangles; %zu that draw)%s", caught[i], caughtTris[i], wrong[i], i < 2 ? "," : "\n");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rtr-lod-cut: the level-of-detail cut rtr-view would draw, per level of the hierarchy (CPU)"};
  std::string file, camera, size = "3840x2160", only;
  std::vector<float> thresholds{1.0f};
  float fov = 0.0f;
  bool rebuild = false, fates = false;
  unsigned threads = 0;
  app.add_option("scene", file, "scene file (.rtrscene with its hierarchy, or any scene: --rebuild)")->required();
  app.add_option("--camera", camera, "x,y,z,yaw,pitch (default: the scene's stored view, as rtr-view)");
  app.add_option("--fov", fov, "vertical field of view, degrees (default: as rtr-view)")->check(cli::number(1, 179));
  app.add_option("--size", size, "WxH of the image");
  app.add_option("--lod-error", thresholds, "thresholds in pixels, repeatable")->check(cli::number(0, 1e6));
  app.add_option("--mesh", only, "only the mesh of this name (a scene without instances)");
  app.add_flag("--fates", fates, "also what the rasteriser does with each listed triangle (a CPU depth buffer)");
  app.add_flag("--rebuild", rebuild, "build the hierarchy again (prints the build per level)");
  app.add_option("--threads", threads, "for --rebuild (0: all cores)")->check(cli::integer(0, 1024));
  return cli::run(app, argc, argv, [&] {
    const cli::Size wh = cli::parseSize("--size", size);
    Scene scene = loadScene(file);
    Lens lens;
    if (fov > 0) lens.fovYDeg = fov;
    else if (camera.empty() && scene.defaultView && scene.defaultFovYDeg > 0.0f) lens.fovYDeg = scene.defaultFovYDeg;
    const float aspect = float(wh.width) / float(wh.height);
    const CameraPose pose = !camera.empty()     ? cli::parsePose("--camera", camera)
                            : scene.defaultView ? *scene.defaultView
                                                : framingPose(scene, lens, aspect);
    lens = fitDepthRange(lens, scene.bounds(), pose);
    const View v{pose.position,
                 projectionMatrix(lens, aspect) * viewMatrix(pose),
                 float(wh.height) / (2.0f * std::tan(glm::radians(lens.fovYDeg) * 0.5f)),
                 lens.zNear,
                 wh.width,
                 wh.height};
    if (!only.empty()) {  // the view stays that of the whole scene
      if (!scene.instances.empty()) throw UsageError("--mesh: " + file + " places its meshes by instances");
      std::erase_if(scene.meshes, [&](const Mesh& m) { return m.name != only; });
      if (scene.meshes.empty()) throw UsageError("--mesh: " + file + " has no mesh named '" + only + "'");
    }
    if (rebuild || std::all_of(scene.meshes.begin(), scene.meshes.end(), [](const Mesh& m) { return m.lod.levels == 0; })) {
      buildMissingClusters(scene);
      std::vector<LodGroupStats> stats;
      const auto t0 = std::chrono::steady_clock::now();
      for (Mesh& m : scene.meshes) {
        if (m.clusters.empty()) continue;
        const bool cones = m.material >= scene.materials.size() || conesCull(scene.materials[m.material]);
        m.lod = buildClusterLod(m, cones, threads, &stats);
      }
      std::printf("hierarchy built in %.3f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      printBuild(stats);
    }
    size_t triangles = 0;
    for (const Mesh& m : scene.meshes) triangles += m.triangleCount();
    std::printf("%s: %zu meshes, %zu triangles; eye %s, fovY %g, %ux%u, %.1f px a unit at distance 1, near %g\n", file.c_str(),
                scene.meshes.size(), triangles, formatPose(pose).c_str(), lens.fovYDeg, wh.width, wh.height, v.pixelsPerUnit,
                lens.zNear);
    printLevels(scene);
    for (float t : thresholds) {
      printCut(scene, v, t);
      if (fates) printFates(scene, v, t);
    }
    return 0;
  });
}
