// The compute rasteriser (render/raster.hpp) against the hardware's visibility ids, and on its own: a
// closed mesh seen from inside is covered exactly once per pixel (docs/raster.md).
#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <tuple>
#include <utility>

#include <gtest/gtest.h>

#include "test_paths.hpp"

#include "core/image.hpp"
#include "raster.h"
#include "render/headless.hpp"
#include "scene/load.hpp"
#include "scene/textures.hpp"
#include "vk/commands.hpp"
#include "vk/pipeline.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using render::RasterPath;

// Where a visibility id's triangle is: its mesh (a scene without instances: one per mesh with indices, in
// order) and index.
struct IdDecoder {
  const render::GpuScene& gpu;
  std::vector<const Mesh*> draws;
  std::vector<bool> maskedDraws;  // its triangles are alpha-tested
  IdDecoder(const Scene& s, const render::GpuScene& g) : gpu(g) {
    for (const Mesh& m : s.meshes)
      if (!m.indices.empty()) {
        draws.push_back(&m);
        maskedDraws.push_back(!m.texcoords.empty() && alphaTested(m, s.materials[m.material]));
      }
  }
  bool masked(uint32_t id) const { return id != VIS_EMPTY && maskedDraws.at(gpu.decodeVisId(id).first); }
  std::array<glm::vec3, 3> triangle(uint32_t id) const {
    const Mesh& m = *draws.at(gpu.decodeVisId(id).first);
    const uint32_t t = gpu.decodeVisId(id).second;
    return {m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]], m.positions[m.indices[3 * t + 2]]};
  }
};

// Screen-space distance (pixels) from `p` to the outline of the triangle's visible part: the triangle
// clipped to w >= 1e-6 in clip space, then projected (framebuffer y down).
double outlineDistance(const glm::dmat4& viewProj, const std::array<glm::vec3, 3>& tri, glm::dvec2 size, glm::dvec2 p) {
  std::vector<glm::dvec4> in, poly;
  for (const glm::vec3& v : tri) in.push_back(viewProj * glm::dvec4(glm::dvec3(v), 1.0));
  const double eps = 1e-6;
  for (size_t i = 0; i < 3; ++i) {  // Sutherland-Hodgman against one plane
    const glm::dvec4 a = in[i], b = in[(i + 1) % 3];
    if (a.w >= eps) poly.push_back(a);
    if ((a.w >= eps) != (b.w >= eps)) poly.push_back(a + (b - a) * ((eps - a.w) / (b.w - a.w)));
  }
  double best = 1e30;
  for (size_t i = 0; i < poly.size(); ++i) {
    auto screen = [&](glm::dvec4 c) { return (glm::dvec2(c) / c.w * 0.5 + 0.5) * size; };
    const glm::dvec2 a = screen(poly[i]), b = screen(poly[(i + 1) % poly.size()]), d = b - a;
    const double t = glm::dot(d, d) > 0 ? std::clamp(glm::dot(p - a, d) / glm::dot(d, d), 0.0, 1.0) : 0.0;
    best = std::min(best, glm::length(p - (a + t * d)));
  }
  return best;
}

// Depth (z/w, as the rasteriser interpolates it) of the triangle's plane where the ray through screen
// point p meets it.
double planeDepth(const glm::dmat4& viewProj, const std::array<glm::vec3, 3>& tri, glm::dvec2 size, glm::dvec2 p) {
  const glm::dmat4 inv = glm::inverse(viewProj);
  const glm::dvec2 ndc = p / size * 2.0 - 1.0;
  const glm::dvec4 a = inv * glm::dvec4(ndc, 0, 1), b = inv * glm::dvec4(ndc, 1, 1);
  const glm::dvec3 o = glm::dvec3(a) / a.w, dir = glm::dvec3(b) / b.w - o;
  const glm::dvec3 p0(tri[0]), n = glm::cross(glm::dvec3(tri[1]) - p0, glm::dvec3(tri[2]) - p0);
  const glm::dvec4 hit = viewProj * glm::dvec4(o + dir * (glm::dot(p0 - o, n) / glm::dot(dir, n)), 1.0);
  return hit.z / hit.w;
}

// Whether `id` is in `img` (w pixels a row) within one pixel of (x, y): a mask's edge moved by at most a pixel.
bool idWithinOnePixel(const std::vector<uint32_t>& img, uint32_t w, int x, int y, uint32_t id) {
  const int h = int(img.size() / w);
  for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v)
    for (int u = std::max(0, x - 1); u <= std::min(int(w) - 1, x + 1); ++u)
      if (img[size_t(v) * w + u] == id) return true;
  return false;
}

// Two id images of one view compared: pixels covered in either, the same id, differing off every edge
// (below), differing only at the edge of an alpha mask's cut-out. A difference is allowed where the pixel
// centre is within 1/64 pixel of an edge of one of the two triangles (vertices are snapped to 1/256 pixel;
// a tie on a shared edge or a snapping difference) or is a depth tie (the two triangles' planes within 1e-5
// in z/w there: where they interpenetrate or nearly coincide) or lies at a mask's edge; the first few
// others are reported as failures.
struct IdComparison {
  size_t covered = 0, same = 0, offEdge = 0, maskEdges = 0;
};
IdComparison compareIds(const IdDecoder& decode, const glm::dmat4& vp, VkExtent2D extent, const std::vector<uint32_t>& hw,
                        const std::vector<uint32_t>& cs) {
  const glm::dvec2 size(extent.width, extent.height);
  IdComparison r;
  for (uint32_t y = 0; y < extent.height; ++y)
    for (uint32_t x = 0; x < extent.width; ++x) {
      const size_t i = size_t(y) * extent.width + x;
      if (hw[i] == VIS_EMPTY && cs[i] == VIS_EMPTY) continue;
      ++r.covered;
      if (hw[i] == cs[i]) {
        ++r.same;
        continue;
      }
      double d = 1e30;
      for (uint32_t id : {hw[i], cs[i]})
        if (id != VIS_EMPTY) d = std::min(d, outlineDistance(vp, decode.triangle(id), size, {x + 0.5, y + 0.5}));
      // Or a depth tie: the two triangles' planes meet (or nearly coincide) at the pixel centre.
      const double dz = hw[i] == VIS_EMPTY || cs[i] == VIS_EMPTY
                            ? 1.0
                            : std::abs(planeDepth(vp, decode.triangle(hw[i]), size, {x + 0.5, y + 0.5}) -
                                       planeDepth(vp, decode.triangle(cs[i]), size, {x + 0.5, y + 0.5}));
      // Or the edge of an alpha-masked triangle's cut-out (the mask sampled by two rasterisers).
      const bool maskEdge = (decode.masked(hw[i]) || decode.masked(cs[i])) &&
                            (idWithinOnePixel(hw, extent.width, x, y, cs[i]) || idWithinOnePixel(cs, extent.width, x, y, hw[i]));
      r.maskEdges += maskEdge && d > 1.0 / 64 && dz > 1e-5;
      if (d > 1.0 / 64 && dz > 1e-5 && !maskEdge) {
        if (++r.offEdge < 10)
          ADD_FAILURE() << "pixel " << x << "," << y << ": " << hw[i] << " against " << cs[i] << ", " << d
                        << " px from the nearest edge, depths " << dz << " apart";
      }
    }
  return r;
}

class RasterTest : public test::VulkanTest {
 protected:
  void SetUp() override {
    VulkanTest::SetUp();
    if (!render::ComputeRaster::supported(*ctx)) GTEST_SKIP() << "no 64-bit buffer atomics";
  }
  std::vector<uint32_t> ids(render::HeadlessRenderer& r, const CameraPose& pose, const Lens& lens, RasterPath raster,
                            bool clip = true, render::Culling cull = render::Culling::Off) {
    render::RenderSettings s;
    s.raster = raster;
    s.clip = clip;
    s.cull = cull;
    s.mosaic = render::MosaicMode::Off;
    return r.ids(pose, lens, s);
  }
};

// Same views, both rasterisers: at least 99.9 % of covered pixels carry the same triangle, and every pixel
// that differs is on an edge, a depth tie or a mask's edge (compareIds), nothing else.
TEST_F(RasterTest, HardwareAndComputeIdsAgree) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  const VkExtent2D extent{320, 180};
  render::HeadlessRenderer r(*ctx, gpu, extent);
  const IdDecoder decode(scene, gpu);
  const CameraPose framed = scene.defaultView.value_or(frameBounds(scene.bounds(), Lens{}, 320.0f / 180.0f));
  const glm::vec3 c = scene.bounds().center();
  // Framed; inside, low, turned (floor and walls cross the near plane); close to a pillar, steep.
  const CameraPose poses[] = {framed, {c + glm::vec3(0, 0.3f, 0), 70.0f, -10.0f}, {c + glm::vec3(2, -0.5f, 1), 200.0f, -35.0f}};
  for (const CameraPose& pose : poses) {
    SCOPED_TRACE(testing::Message() << "pose " << pose.position.x << "," << pose.position.y << "," << pose.position.z);
    Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
    lens.zNear = 0.05f;  // near enough that geometry crosses it
    const std::vector<uint32_t> hw = ids(r, pose, lens, RasterPath::Hardware);
    render::RenderSettings asked;
    asked.raster = RasterPath::Compute;
    ASSERT_EQ(r.renderer().rasterFor(asked), RasterPath::Compute);
    const std::vector<uint32_t> cs = ids(r, pose, lens, RasterPath::Compute);
    const glm::dmat4 vp = glm::dmat4(projectionMatrix(lens, 320.0f / 180.0f) * viewMatrix(pose));
    const auto [covered, same, offEdge, maskEdges] = compareIds(decode, vp, extent, hw, cs);
    std::printf("ids: %zu of %zu covered pixels agree (%.4f %%), %zu differing off an edge, %zu at a mask's edge\n", same,
                covered, 100.0 * same / covered, offEdge, maskEdges);
    EXPECT_GT(covered, size_t(extent.width) * extent.height / 4) << "too little drawn to compare";
    EXPECT_GE(double(same), 0.999 * double(covered));
    EXPECT_EQ(offEdge, 0u);
  }
}

// The triangles crossing w = 0 or leaving the guard band are clipped in compute (raster_clip.comp): the
// temple's views above, and one low over the floor with the near plane at 0.01 (floor triangles beside the
// camera leave the guard band with w > 0). None is handed to the hardware, the clipping pass counts them,
// and the ids are those of the hardware's hand-off (RenderSettings::clip off) but on edges.
TEST_F(RasterTest, CrossingTrianglesAreClippedInCompute) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  const VkExtent2D extent{320, 180};
  render::HeadlessRenderer r(*ctx, gpu, extent);
  const IdDecoder decode(scene, gpu);
  const CameraPose framed = scene.defaultView.value_or(frameBounds(scene.bounds(), Lens{}, 320.0f / 180.0f));
  const glm::vec3 c = scene.bounds().center(), lo = scene.bounds().min;
  const CameraPose poses[] = {framed,
                              {c + glm::vec3(0, 0.3f, 0), 70.0f, -10.0f},
                              {c + glm::vec3(2, -0.5f, 1), 200.0f, -35.0f},
                              {glm::vec3(c.x + 1, lo.y + 0.02f, c.z), 10.0f, 0.0f}};
  uint32_t total = 0;
  for (const CameraPose& pose : poses) {
    SCOPED_TRACE(testing::Message() << "pose " << pose.position.x << "," << pose.position.y << "," << pose.position.z);
    Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
    lens.zNear = &pose == &poses[3] ? 0.01f : 0.05f;
    const std::vector<uint32_t> hw = ids(r, pose, lens, RasterPath::Compute, false);
    const uint32_t handedOff = r.renderer().handOffTriangles(0).value_or(0);
    EXPECT_EQ(r.renderer().clippedTriangles(0), 0u) << "clipping off";
    const std::vector<uint32_t> cs = ids(r, pose, lens, RasterPath::Compute);
    const uint32_t clipped = r.renderer().clippedTriangles(0).value_or(0);
    EXPECT_EQ(r.renderer().handOffTriangles(0), 0u) << "a triangle handed to the hardware";
    EXPECT_EQ(clipped, handedOff) << "the clipping pass takes what the hardware was handed";
    total += clipped;
    const glm::dmat4 vp = glm::dmat4(projectionMatrix(lens, 320.0f / 180.0f) * viewMatrix(pose));
    const auto [covered, same, offEdge, maskEdges] = compareIds(decode, vp, extent, hw, cs);
    std::printf(
        "clipped %u triangles: %zu of %zu covered pixels as the hardware's hand-off (%.4f %%), %zu off an edge, %zu at a mask's edge\n",
        clipped, same, covered, 100.0 * same / covered, offEdge, maskEdges);
    EXPECT_GE(double(same), 0.999 * double(covered));
    EXPECT_EQ(offEdge, 0u);
    // With two-phase culling the clipping pass runs in both phases: the first frame's late phase draws
    // everything, the second's early phase (the late dispatch then skips the early entries). Same ids.
    for (int frame = 0; frame < 2; ++frame) {
      EXPECT_EQ(ids(r, pose, lens, RasterPath::Compute, true, render::Culling::TwoPhase), cs) << "culled, frame " << frame;
      EXPECT_EQ(r.renderer().handOffTriangles(0), 0u) << "culled, frame " << frame;
    }
  }
  EXPECT_GT(total, 20u) << "too few crossing triangles to test";
}

// Hot reload (rebuildPipelines) replaces the compute rasteriser too: the next frame's ids are the same.
TEST_F(RasterTest, RebuiltPipelinesGiveTheSameIds) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  render::HeadlessRenderer r(*ctx, gpu, {160, 90});
  const CameraPose pose = scene.defaultView.value_or(frameBounds(scene.bounds(), Lens{}, 160.0f / 90.0f));
  const Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
  const std::vector<uint32_t> before = ids(r, pose, lens, RasterPath::Compute);
  r.renderer().rebuildPipelines();
  const std::vector<uint32_t> after = ids(r, pose, lens, RasterPath::Compute);
  EXPECT_EQ(before, after);
  EXPECT_GT(std::count_if(after.begin(), after.end(), [](uint32_t id) { return id != VIS_EMPTY; }), 160 * 90 / 4);
}

// RenderSettings::counters off (rtr-view --bench's timed frames): the frame reads no counter back, so none
// is reported for it, and its ids are those of a counted frame, with and without two-phase culling.
TEST_F(RasterTest, FramesWithoutCountersDrawTheSameIdsAndReportNone) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  render::HeadlessRenderer r(*ctx, gpu, {160, 90});
  const CameraPose pose = scene.defaultView.value_or(frameBounds(scene.bounds(), Lens{}, 160.0f / 90.0f));
  const Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
  for (render::Culling cull : {render::Culling::Off, render::Culling::Frustum, render::Culling::TwoPhase}) {
    SCOPED_TRACE(std::string("culling ") + enumName(cull));
    render::RenderSettings s;
    s.raster = RasterPath::Compute;
    s.clip = true;
    s.cull = cull;
    s.mosaic = render::MosaicMode::Off;
    const std::vector<uint32_t> counted = r.ids(pose, lens, s);
    ASSERT_TRUE(r.renderer().handOffTriangles(0) && r.renderer().mediumTriangles(0));
    EXPECT_EQ(r.renderer().cullStats(0).has_value(), cull != render::Culling::Off);
    const uint32_t medium = r.renderer().mediumTriangles(0)->total();
    s.counters = false;
    EXPECT_EQ(r.ids(pose, lens, s), counted);
    EXPECT_FALSE(r.renderer().handOffTriangles(0) || r.renderer().clippedTriangles(0) || r.renderer().mediumTriangles(0) ||
                 r.renderer().cullStats(0));
    s.counters = true;
    EXPECT_EQ(r.ids(pose, lens, s), counted);
    ASSERT_TRUE(r.renderer().mediumTriangles(0));
    EXPECT_EQ(r.renderer().mediumTriangles(0)->total(), medium) << "the counters after an uncounted frame";
  }
}

// The medium list's settings (render/raster.cpp; nullptr: unset), read when the renderer makes its pipelines.
struct MediumSetting {
  const char* from;      // RTR_RASTER_MEDIUM: boxes over this many pixels are medium ("0": no list)
  const char* lanes;     // RTR_RASTER_MEDIUM_LANES: boxes of up to 64 pixels by 16 lanes (unset, "16") or 32
  const char* capacity;  // RTR_RASTER_MEDIUM_CAPACITY: records (unset: the scene's triangles, at most 256 Ki)
};
using MediumCounts = render::ComputeRaster::MediumCounts;

// Ids with raster.comp's medium triangles drawn by raster_large.comp and by their own thread: `render` draws
// with each setting and returns the ids and the medium triangles counted; the ids must be those of the first
// setting (the list off) byte for byte. Returns the counts.
template <class Render>
std::vector<MediumCounts> expectSameIdsWithAndWithoutMedium(const std::vector<MediumSetting>& settings, Render render,
                                                            size_t minCovered) {
  std::vector<std::vector<uint32_t>> got;
  std::vector<MediumCounts> medium;
  for (const MediumSetting& m : settings) {
    const std::pair<const char*, const char*> vars[] = {
        {"RTR_RASTER_MEDIUM", m.from}, {"RTR_RASTER_MEDIUM_LANES", m.lanes}, {"RTR_RASTER_MEDIUM_CAPACITY", m.capacity}};
    for (const auto& [name, value] : vars) {
      if (value) ::setenv(name, value, 1);
      else ::unsetenv(name);
    }
    auto [v, counts] = render();
    got.push_back(std::move(v));
    medium.push_back(counts);
    for (const auto& [name, value] : vars) ::unsetenv(name);
    std::printf(
        "RTR_RASTER_MEDIUM=%s RTR_RASTER_MEDIUM_LANES=%s RTR_RASTER_MEDIUM_CAPACITY=%s: medium triangles %u of 16 "
        "lanes, %u of 32, %u past the list\n",
        m.from ? m.from : "", m.lanes ? m.lanes : "", m.capacity ? m.capacity : "", counts.narrow, counts.wide, counts.pastList);
  }
  auto differing = [](const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
    size_t n = a.size() == b.size() ? 0 : std::max(a.size(), b.size());
    for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) n += a[i] != b[i];
    return n;
  };
  EXPECT_EQ(std::string(settings.at(0).from), "0") << "the first setting: no medium list";
  EXPECT_EQ(medium[0].total(), 0u) << "RTR_RASTER_MEDIUM=0 lists none";
  for (size_t i = 1; i < settings.size(); ++i)
    EXPECT_EQ(differing(got[i], got[0]), 0u) << "pixels whose ids the medium list changes, setting " << i;
  EXPECT_GT(size_t(std::count_if(got[0].begin(), got[0].end(), [](uint32_t id) { return id != VIS_EMPTY; })), minCovered);
  return medium;
}

// The temple's three views, with and without culling (both phases append to the list): the same atomics
// in another order give the same ids, byte for byte, with the list off, at its default threshold with 16
// and 32 lanes for the smaller boxes, and at 1 pixel.
TEST_F(RasterTest, MediumTrianglesGiveTheSameIds) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  const VkExtent2D extent{480, 270};
  const glm::vec3 c = scene.bounds().center();
  const CameraPose poses[] = {scene.defaultView.value_or(frameBounds(scene.bounds(), Lens{}, 480.0f / 270.0f)),
                              {c + glm::vec3(0, 0.3f, 0), 70.0f, -10.0f},
                              {c + glm::vec3(2, -0.5f, 1), 200.0f, -35.0f}};
  const std::vector<MediumCounts> medium = expectSameIdsWithAndWithoutMedium(
      {{"0", nullptr, nullptr}, {nullptr, nullptr, nullptr}, {nullptr, "32", nullptr}, {"1", nullptr, nullptr}},
      [&] {
        render::HeadlessRenderer r(*ctx, gpu, extent);
        std::vector<uint32_t> all;
        MediumCounts medium;
        for (const CameraPose& pose : poses) {
          const Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
          const std::vector<uint32_t> v = ids(r, pose, lens, RasterPath::Compute);
          const MediumCounts m = r.renderer().mediumTriangles(0).value_or(MediumCounts{});
          medium.narrow += m.narrow, medium.wide += m.wide, medium.pastList += m.pastList;
          all.insert(all.end(), v.begin(), v.end());
          for (int frame = 0; frame < 2; ++frame)  // the first frame's late phase draws all, the second's early phase
            EXPECT_EQ(ids(r, pose, lens, RasterPath::Compute, true, render::Culling::TwoPhase), v) << "culled, frame " << frame;
        }
        return std::pair(all, medium);
      },
      3 * 480 * 270 / 4);
  EXPECT_GT(medium[1].narrow, 100u) << "too few medium triangles of 16 lanes to test";
  EXPECT_GT(medium[1].wide, 100u) << "too few medium triangles of 32 lanes to test";
  EXPECT_EQ(medium[2].narrow, 0u) << "RTR_RASTER_MEDIUM_LANES=32: every record of 32 lanes";
  EXPECT_EQ(medium[2].wide, medium[1].total());
  EXPECT_GT(medium[3].total(), medium[1].total());
  for (const MediumCounts& m : medium) EXPECT_EQ(m.pastList, 0u) << "the temple's triangles fit the list";
}

// More medium triangles than the list holds (RTR_RASTER_MEDIUM_CAPACITY): a subgroup whose records would not
// all fit draws them itself, with either lane count, without a record of one kind overwriting one of the
// other (they fill the list from its two ends). Boxes of 6-7 pixels a side (16 lanes), 13-14 (32 lanes)
// and, in every third run of a subgroup's size, at most 2×2 (drawn in place), at random places and depths,
// overlapping, seen straight through an orthographic lens.
TEST_F(RasterTest, MediumTrianglesPastTheListAreDrawnInPlace) {
  VkPhysicalDeviceSubgroupProperties sub{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &sub};
  vkGetPhysicalDeviceProperties2(ctx->physicalDevice(), &props);
  const uint32_t lanes = sub.subgroupSize;
  constexpr uint32_t kSize = 128, kTriangles = 1u << 16, kCapacity = 20000;
  static_assert(6 * 6 > RASTER_MEDIUM_FROM && 7 * 7 <= RASTER_MEDIUM_NARROW_AREA && 2 * 2 <= RASTER_MEDIUM_FROM &&
                13 * 13 > RASTER_MEDIUM_NARROW_AREA && 14 * 14 <= RASTER_SHARED_AREA);
  Scene scene;
  scene.materials.push_back(Material{});
  Mesh m;
  uint32_t seed = 12345;
  auto random = [&](float lo, float hi) {
    seed = seed * 1664525u + 1013904223u;
    return lo + (hi - lo) * float(seed >> 8) / float(1u << 24);
  };
  uint32_t narrowMade = 0, wideMade = 0;
  for (uint32_t t = 0; t < kTriangles; ++t) {
    const bool tiny = (t % 124 / lanes) % 3 == 2, narrow = !tiny && random(0, 1) < 0.5f;
    narrowMade += narrow;
    wideMade += !tiny && !narrow;
    const float side = tiny ? 1.4f : narrow ? 6.4f : 13.4f;  // pixels: boxes of 1-2, 6-7 and 13-14 pixel centres a side
    const float x = random(1, kSize - 15), y = random(1, kSize - 15), z = random(-2, -1);
    auto world = [&](float sx, float sy) { return glm::vec3(sx / (kSize / 2) - 1, 1 - sy / (kSize / 2), z); };
    const uint32_t v = uint32_t(m.positions.size());
    // Counter-clockwise on screen (y down): front-facing.
    for (const glm::vec3& p : {world(x, y), world(x, y + side), world(x + side, y)}) {
      m.positions.push_back(p);
      m.normals.push_back(glm::vec3(0, 0, 1));
    }
    m.indices.insert(m.indices.end(), {v, v + 1, v + 2});
  }
  ASSERT_GT(std::min(narrowMade, wideMade), kCapacity);
  for (const glm::vec3& p : m.positions) m.bounds.extend(p);
  scene.meshes.push_back(std::move(m));
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  Lens lens;
  lens.orthographic = true;
  lens.zNear = 0.5f;
  lens.zFar = 3.0f;
  const std::string capacity = std::to_string(kCapacity);
  const std::vector<MediumCounts> medium = expectSameIdsWithAndWithoutMedium(
      {{"0", nullptr, nullptr},
       {nullptr, nullptr, nullptr},
       {nullptr, nullptr, capacity.c_str()},
       {nullptr, "32", capacity.c_str()},
       {"1", nullptr, capacity.c_str()}},
      [&] {
        render::HeadlessRenderer r(*ctx, gpu, {kSize, kSize});
        std::vector<uint32_t> v = ids(r, {{0, 0, 0}, 0, 0}, lens, RasterPath::Compute);
        return std::pair(std::move(v), r.renderer().mediumTriangles(0).value_or(MediumCounts{}));
      },
      kSize * kSize / 2);
  EXPECT_EQ(medium[1].narrow, narrowMade) << "every 6-7 pixel box counted";
  EXPECT_EQ(medium[1].wide, wideMade) << "every 13-14 pixel box counted";
  EXPECT_EQ(medium[1].pastList, 0u) << "the list holds as many records as the scene has triangles";
  for (size_t i = 2; i < medium.size(); ++i) {
    EXPECT_GE(medium[i].total(), narrowMade + wideMade) << "setting " << i;
    EXPECT_GT(medium[i].pastList, 0u) << "setting " << i;
    // The subgroups before the first that did not fit filled the list but for less than a subgroup's records.
    EXPECT_LE(medium[i].total() - medium[i].pastList, kCapacity) << "setting " << i;
    EXPECT_GT(medium[i].total() - medium[i].pastList + lanes, kCapacity) << "setting " << i;
  }
  EXPECT_EQ(medium[2].narrow, narrowMade);
  EXPECT_EQ(medium[3].narrow, 0u);
  EXPECT_EQ(medium[3].wide, narrowMade + wideMade);
}

// A closed cube [-1, 1]³ seen from inside: its faces wound to face the centre. Every axis is cut at the same
// coordinates (no T-junctions), given as pixel positions s of the 64×64 view from the centre looking at -z
// with a 90° lens (x = s / 32 - 1 on the z = -1 face): pixel centres (vertices exactly on them), a run of
// 1/16-pixel steps (tiny and thin triangles), and the cube's edges; all on the 1/256-pixel grid. Zero-area
// triangles (a repeated vertex, three points on a line) are added to each face. The z = -1 face comes first.
constexpr uint32_t kCubeSize = 64;
std::vector<double> cubeCuts() {
  std::vector<double> s = {0, 64};
  for (int k = 0; k < 64; k += 8) s.push_back(k + 0.5);
  s.push_back(63.5);
  for (int i = 1; i < 16; ++i) s.push_back(20 + i / 16.0);
  std::sort(s.begin(), s.end());
  s.erase(std::unique(s.begin(), s.end()), s.end());
  return s;
}

Scene insideCube() {
  const std::vector<double> cuts = cubeCuts();
  Scene scene;
  scene.materials.push_back(Material{});
  Mesh m;
  const uint32_t n = uint32_t(cuts.size());
  for (int face = 0; face < 6; ++face) {
    const int axis = face < 2 ? 2 : face < 4 ? 0 : 1;  // -z, +z, -x, +x, -y, +y
    const float side = face % 2 ? 1.0f : -1.0f;
    const uint32_t base = uint32_t(m.positions.size());
    for (uint32_t j = 0; j < n; ++j)
      for (uint32_t i = 0; i < n; ++i) {
        glm::vec3 p;
        p[axis] = side;
        p[(axis + 1) % 3] = float(cuts[i] / 32 - 1);
        p[(axis + 2) % 3] = float(1 - cuts[j] / 32);
        m.positions.push_back(p);
        m.normals.push_back(glm::vec3(0.0f));
      }
    auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
      const glm::vec3 nrm = glm::cross(m.positions[b] - m.positions[a], m.positions[c] - m.positions[a]);
      if (nrm[axis] * side > 0) std::swap(b, c);  // facing the centre
      m.indices.insert(m.indices.end(), {a, b, c});
    };
    for (uint32_t j = 0; j + 1 < n; ++j)
      for (uint32_t i = 0; i + 1 < n; ++i) {
        const uint32_t v = base + j * n + i;
        add(v, v + 1, v + n + 1);
        add(v, v + n + 1, v + n);
      }
    m.indices.insert(m.indices.end(), {base, base, base + n + 1, base + 1, base + 2, base + 3});  // zero area
  }
  for (const glm::vec3& p : m.positions) m.bounds.extend(p);
  scene.meshes.push_back(std::move(m));
  return scene;
}

// Which triangles of `mesh`'s first `count` cover pixel centre (x, y) of the straight view by the documented
// rule (docs/raster.md), from the construction's exact pixel positions: vertices on the 1/256-pixel grid,
// edge functions positive inside (clockwise on screen, y down), ties to top and left edges.
std::vector<uint32_t> owners(const Mesh& mesh, uint32_t count, uint32_t x, uint32_t y) {
  std::vector<uint32_t> out;
  for (uint32_t t = 0; t < count; ++t) {
    glm::i64vec2 v[3];
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 p = mesh.positions[mesh.indices[3 * t + k]];  // on z = -1: screen = 32 (x + 1), 32 (1 - y)
      v[k] = glm::i64vec2(std::llround((p.x + 1.0) * 32 * 256), std::llround((1.0 - p.y) * 32 * 256));
    }
    const int64_t area = (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[1].y - v[0].y) * (v[2].x - v[0].x);
    if (area == 0) continue;
    if (area < 0) std::swap(v[1], v[2]);
    const glm::i64vec2 c(int64_t(x) * 256 + 128, int64_t(y) * 256 + 128);
    bool inside = true;
    for (int k = 0; k < 3; ++k) {
      const glm::i64vec2 a = v[(k + 1) % 3], d = v[(k + 2) % 3] - a;
      const int64_t e = d.x * (c.y - a.y) - d.y * (c.x - a.x);
      inside &= e > 0 || (e == 0 && (d.y < 0 || (d.y == 0 && d.x > 0)));
    }
    if (inside) out.push_back(t);
  }
  return out;
}

// No pixel left uncovered from inside the closed cube: straight (vertices on pixel centres), turned, and
// from near a corner (not nearer than the near plane reaches), where faces cross the plane w = 0 (handed to
// compute, raster_clip.comp) and lie behind the camera.
TEST_F(RasterTest, ClosedMeshFromInsideLeavesNoHole) {
  const Scene scene = insideCube();
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  render::HeadlessRenderer r(*ctx, gpu, {kCubeSize, kCubeSize});
  Lens lens;
  lens.fovYDeg = 90.0f;
  lens.zNear = 0.05f;
  lens.zFar = 10.0f;
  const CameraPose poses[] = {{{0, 0, 0}, 0, 0},
                              {{0, 0, 0}, 30, 20},
                              {{0, 0, 0}, -45, 60},
                              {{0.7f, -0.6f, 0.5f}, 150, -30},
                              {{0.85f, 0.85f, -0.85f}, 45, 35}};
  uint32_t clipped = 0;
  for (const bool clip : {true, false})  // clipped in compute, and handed to the hardware (the default)
    for (const CameraPose& pose : poses) {
      SCOPED_TRACE(testing::Message() << "yaw " << pose.yawDeg << ", pitch " << pose.pitchDeg
                                      << (clip ? ", compute clip" : ", hardware"));
      const std::vector<uint32_t> cs = ids(r, pose, lens, RasterPath::Compute, clip);
      if (clip) clipped += r.renderer().clippedTriangles(0).value_or(0);
      size_t holes = 0;
      for (uint32_t i = 0; i < cs.size(); ++i)
        if (cs[i] == VIS_EMPTY && ++holes <= 5) ADD_FAILURE() << "hole at " << i % kCubeSize << "," << i / kCubeSize;
      EXPECT_EQ(holes, 0u);
    }
  EXPECT_GT(clipped, 0u) << "no face crosses w = 0: clipping untested";
}

// Seen straight, every pixel centre of the z = -1 face is owned by exactly one triangle by the rule, and the
// compute rasteriser gives it to that one: on shared edges and vertices too (a rule covering both sides
// of an edge would leave the smaller id there, one covering neither a hole).
TEST_F(RasterTest, SharedEdgesAreCoveredOnceByTheTopLeftRule) {
  const Scene scene = insideCube();
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  render::HeadlessRenderer r(*ctx, gpu, {kCubeSize, kCubeSize});
  Lens lens;
  lens.fovYDeg = 90.0f;
  lens.zNear = 0.05f;
  const std::vector<uint32_t> cs = ids(r, {{0, 0, 0}, 0, 0}, lens, RasterPath::Compute);
  const Mesh& mesh = scene.meshes[0];
  const uint32_t n = uint32_t(cubeCuts().size()), faceTriangles = 2 * (n - 1) * (n - 1) + 2;
  size_t wrong = 0, onEdge = 0;
  for (uint32_t y = 0; y < kCubeSize; ++y)
    for (uint32_t x = 0; x < kCubeSize; ++x) {
      const std::vector<uint32_t> o = owners(mesh, faceTriangles, x, y);
      ASSERT_EQ(o.size(), 1u) << "the reference rule is not watertight at " << x << "," << y;
      onEdge += x % 8 == 0 || y % 8 == 0 || x == 63 || y == 63;  // the centre is on a cut: a shared edge
      const uint32_t got = cs[y * kCubeSize + x];
      if (got != o[0] && ++wrong <= 5)
        ADD_FAILURE() << "pixel " << x << "," << y << ": triangle " << got << ", the rule gives " << o[0];
    }
  EXPECT_EQ(wrong, 0u);
  EXPECT_GT(onEdge, 500u) << "too few pixel centres on shared edges to test the rule";
}

// Alpha-masked geometry drawn in compute (docs/raster.md, "The alpha test"): a 64×64 mask of 4-texel
// checks (alpha 0.9 and 0), repeated, on a quad facing the camera (an 8×8 grid of small triangles, the
// texture magnified) and a long floor (two large triangles, the tile pass; minified from 1 to past 16
// texels a pixel, anisotropic): where the mask is minified past level 2 the checks average to 0.45 < 0.5
// and the hardware cuts everything, so a level chosen otherwise than the hardware's shows up as whole
// regions. Both rasterisers' ids: at most 0.3 % of covered pixels differ, and each differing pixel lies
// on the edge of a cut-out region (the other rasteriser's id within one pixel in one of the images).
Scene checkerScene(const std::filesystem::path& dir) {
  ImageRGBA8 tex{64, 64, std::vector<uint8_t>(64 * 64 * 4)};
  for (uint32_t y = 0; y < 64; ++y)
    for (uint32_t x = 0; x < 64; ++x) {
      uint8_t* p = tex.at(x, y);
      p[0] = 200, p[1] = 180, p[2] = 160, p[3] = (x / 4 + y / 4) % 2 ? 230 : 0;
    }
  savePng(dir / "checker.png", tex);
  Scene s;
  s.baseDir = dir;
  s.textures.push_back({"checker.png", true, 4});
  Material m;
  m.name = "checker";
  m.flags = kMaterialAlphaMasked | kMaterialDoubleSided;
  m.textures[uint32_t(TextureSlot::BaseColor)] = 0;
  m.textures[uint32_t(TextureSlot::AlphaMask)] = 0;
  s.materials.push_back(m);
  Mesh q;
  constexpr uint32_t n = 8;
  for (uint32_t j = 0; j <= n; ++j)
    for (uint32_t i = 0; i <= n; ++i) {
      q.positions.push_back({2.0f * i / n - 1, 1 - 2.0f * j / n, 0});
      q.texcoords.push_back({float(i) / n, float(j) / n});
    }
  for (uint32_t j = 0; j < n; ++j)
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t v = j * (n + 1) + i;
      q.indices.insert(q.indices.end(), {v, v + n + 2, v + 1, v, v + n + 1, v + n + 2});
    }
  const uint32_t f = uint32_t(q.positions.size());
  q.positions.insert(q.positions.end(), {{-4, -1, 2}, {4, -1, 2}, {4, -1, -40}, {-4, -1, -40}});
  q.texcoords.insert(q.texcoords.end(), {{0, 0}, {2, 0}, {2, 10.5f}, {0, 10.5f}});
  q.indices.insert(q.indices.end(), {f, f + 1, f + 2, f, f + 2, f + 3});
  q.normals.assign(q.positions.size(), glm::vec3(0, 0, 1));
  for (const glm::vec3& p : q.positions) q.bounds.extend(p);
  s.meshes.push_back(q);
  return s;
}

TEST_F(RasterTest, AlphaMaskedIdsAgreeWithTheHardware) {
  const auto dir = std::filesystem::temp_directory_path() / "rtr_raster_mask_test";
  std::filesystem::create_directories(dir);
  const Scene scene = checkerScene(dir);
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  const uint32_t w = 256, h = 192;
  render::HeadlessRenderer r(*ctx, gpu, {w, h});
  const CameraPose poses[] = {{{0, 0, 2.5f}, 0, -10}, {{0.5f, 0.2f, 3}, 25, -20}, {{-1, -0.6f, 1}, -20, -5}};
  for (const CameraPose& pose : poses) {
    SCOPED_TRACE(testing::Message() << "yaw " << pose.yawDeg << ", pitch " << pose.pitchDeg);
    const Lens lens;
    const std::vector<uint32_t> hw = ids(r, pose, lens, RasterPath::Hardware);
    const std::vector<uint32_t> cs = ids(r, pose, lens, RasterPath::Compute);
    EXPECT_LE(r.renderer().handOffTriangles(0), 2u) << "only the floor's two triangles may cross w = 0";
    size_t covered = 0, cut = 0, differ = 0, inside = 0;
    for (int y = 0; y < int(h); ++y)
      for (int x = 0; x < int(w); ++x) {
        const size_t i = size_t(y) * w + x;
        covered += hw[i] != VIS_EMPTY || cs[i] != VIS_EMPTY;
        cut += hw[i] == VIS_EMPTY;
        if (hw[i] == cs[i]) continue;
        ++differ;
        if (!idWithinOnePixel(hw, w, x, y, cs[i]) && !idWithinOnePixel(cs, w, x, y, hw[i]))
          if (++inside <= 5) ADD_FAILURE() << "pixel " << x << "," << y << ": hardware " << hw[i] << ", compute " << cs[i];
      }
    std::printf("masked ids: %zu of %zu covered pixels differ (%.3f %%), %zu inside a region; %zu cut out by the hardware\n",
                differ, covered, 100.0 * differ / covered, inside, cut);
    EXPECT_GT(cut, size_t(w) * h / 4) << "the mask cuts too little to test";
    EXPECT_GT(covered, size_t(w) * h / 8) << "too little drawn to compare";
    EXPECT_LE(double(differ), 0.003 * double(covered));
    EXPECT_EQ(inside, 0u);
  }
  std::filesystem::remove_all(dir);
}

// The default temple's alpha-masked foliage is rasterised in compute: three views, near plane 0.05, hand
// at most the triangles that cross w = 0 or leave the guard band (counted here on the CPU by the rule) to
// the hardware, none of the masked triangles in view that do neither.
TEST_F(RasterTest, MaskedFoliageStaysInCompute) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  ASSERT_TRUE(gpu.hasDraws(render::DrawKind::AlphaMasked));
  const uint32_t w = 320, h = 180;
  render::HeadlessRenderer r(*ctx, gpu, {w, h});
  const CameraPose framed = scene.defaultView.value_or(frameBounds(scene.bounds(), Lens{}, float(w) / float(h)));
  const glm::vec3 c = scene.bounds().center();
  const CameraPose poses[] = {framed, {c + glm::vec3(0, 0.3f, 0), 70.0f, -10.0f}, {c + glm::vec3(2, -0.5f, 1), 200.0f, -35.0f}};
  for (const CameraPose& pose : poses) {
    SCOPED_TRACE(testing::Message() << "pose " << pose.position.x << "," << pose.position.y << "," << pose.position.z);
    Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
    lens.zNear = 0.05f;
    ids(r, pose, lens, RasterPath::Compute);
    const std::optional<uint32_t> handedOff = r.renderer().handOffTriangles(0);
    ASSERT_TRUE(handedOff);
    const glm::mat4 vp = projectionMatrix(lens, float(w) / float(h)) * viewMatrix(pose);
    size_t crossing = 0, masked = 0;  // triangles in the view volume: crossing w = 0 or the guard band; masked others
    for (const Mesh& m : scene.meshes) {
      const bool isMasked = !m.texcoords.empty() && alphaTested(m, scene.materials[m.material]);
      for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
        glm::vec4 p[3];
        for (int k = 0; k < 3; ++k) p[k] = vp * glm::vec4(m.positions[m.indices[t + k]], 1.0f);
        bool outside = p[0].z < 0 && p[1].z < 0 && p[2].z < 0;
        for (int a = 0; a < 3; ++a) {
          outside |= p[0][a] > p[0].w && p[1][a] > p[1].w && p[2][a] > p[2].w;
          if (a < 2) outside |= p[0][a] < -p[0].w && p[1][a] < -p[1].w && p[2][a] < -p[2].w;
        }
        if (outside) continue;
        bool hand = std::min({p[0].w, p[1].w, p[2].w}) <= 0.0f;
        for (int k = 0; k < 3 && !hand; ++k)
          hand = std::abs(p[k].x / p[k].w) * 0.5f * w > RASTER_GUARD_BAND ||
                 std::abs(p[k].y / p[k].w) * 0.5f * h > RASTER_GUARD_BAND;
        crossing += hand;
        masked += isMasked && !hand;
      }
    }
    std::printf("hand-off: %u triangles; %zu cross w = 0 or the guard band; %zu others masked in the view volume\n", *handedOff,
                crossing, masked);
    EXPECT_GT(masked, 0u) << "no foliage in view to test";
    EXPECT_LE(*handedOff, crossing);
  }
}

// The clipping pass lists a large piece's tiles row by row (raster_columns.glsl: per edge, the column
// bound estimated in float and corrected by the exact integer test). For random snapped triangles, every
// tile row's columns are those holding a pixel column inside each edge at the row's top or bottom centre,
// found pixel by pixel: so every tile with a covered centre, within the run of tiles tileTouches accepts
// (which may add a tile whose centres pass each edge but none all three). The triangles: slivers from the
// guard band, vertices on pixel centres and tile edges, thin and axis-aligned ones.
TEST_F(RasterTest, TouchedColumnsAreExact) {
  constexpr int kOne = 1 << RASTER_SUBPIXEL_BITS, kWidth = 512, kHeight = 256, kRows = 8;  // tile_columns.comp
  std::mt19937 rng(30);
  const int band = int(RASTER_GUARD_BAND) * kOne;
  std::uniform_int_distribution<int> far(-band, band), near(-64 * kOne, (kWidth + 64) * kOne), pixel(-8, kWidth + 8),
      choice(0, 3);
  std::vector<glm::ivec4> tris;
  while (tris.size() < 3 * 40000) {
    glm::ivec2 v[3];
    const int kind = choice(rng);
    for (int i = 0; i < 3; ++i) {
      if (kind == 0) v[i] = {near(rng), near(rng) / 2};  // anywhere near the image
      else if (kind == 1) v[i] = i == 0 ? glm::ivec2(far(rng), far(rng)) : glm::ivec2(near(rng), near(rng) / 2);  // slivers
      else if (kind == 2) v[i] = glm::ivec2(pixel(rng), pixel(rng) / 2) * kOne + kOne / 2;  // on pixel centres
      else v[i] = glm::ivec2(pixel(rng) / 32 * 32, pixel(rng) / 64 * 32) * kOne + (i == 2 ? choice(rng) - 1 : 0);  // tile edges
    }
    if (kind == 3 && choice(rng) == 0) v[2].x = v[1].x;  // vertical and horizontal edges
    if (kind == 3 && choice(rng) == 1) v[2].y = v[0].y;
    const int64_t area = int64_t(v[1].x - v[0].x) * (v[2].y - v[0].y) - int64_t(v[1].y - v[0].y) * (v[2].x - v[0].x);
    if (area == 0) continue;
    if (area < 0) std::swap(v[1], v[2]);  // positive inside, as raster_tri.glsl's project orders them
    const glm::ivec2 lo = glm::min(v[0], glm::min(v[1], v[2])), hi = glm::max(v[0], glm::max(v[1], v[2]));
    const glm::ivec4 box{std::max((lo.x - kOne / 2 + kOne - 1) >> RASTER_SUBPIXEL_BITS, 0),
                         std::max((lo.y - kOne / 2 + kOne - 1) >> RASTER_SUBPIXEL_BITS, 0),
                         std::min((hi.x - kOne / 2) >> RASTER_SUBPIXEL_BITS, kWidth - 1),
                         std::min((hi.y - kOne / 2) >> RASTER_SUBPIXEL_BITS, kHeight - 1)};
    if (box.x > box.z || box.y > box.w) continue;
    tris.insert(tris.end(), {glm::ivec4(v[0], v[1]), glm::ivec4(v[2], 0, 0), box});
  }
  const size_t rows = tris.size() / 3 * kRows;
  vk::Buffer in(*ctx, tris.size() * sizeof(glm::ivec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUse::Upload, "triangles");
  vk::Buffer columns(*ctx, rows * sizeof(glm::ivec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUse::Readback, "columns");
  vk::Buffer touches(*ctx, rows * sizeof(glm::ivec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUse::Readback, "touches");
  std::memcpy(in.mapped(), tris.data(), tris.size() * sizeof(glm::ivec4));
  in.flush();
  vk::LayoutOptions options;
  options.pushDescriptorSets = {0};
  options.runtimeArrayCounts[{1, 0}] = 1;  // raster_tri.glsl's textures, declared, not used here
  vk::Pipeline p = vk::makeComputePipeline(*ctx, vk::loadShader("tile_columns.comp"), options);
  vk::submitAndWait(*ctx, [&](VkCommandBuffer cb) {
    p.bind(cb);
    vk::DescriptorWriter(*ctx, p.layout, 0, VK_NULL_HANDLE)
        .buffer(16, in.handle())
        .buffer(17, columns.handle())
        .buffer(18, touches.handle())
        .push(cb, p);
    p.dispatch(cb, uint32_t(rows));
    vk::bufferBarrier(cb, vk::kComputeWrite, vk::kHostRead);
  });
  columns.invalidate();
  touches.invalidate();
  const auto* got = static_cast<const glm::ivec4*>(columns.mapped());
  const auto* tt = static_cast<const glm::ivec4*>(touches.mapped());
  size_t tested = 0, listed = 0, accepted = 0, wrong = 0, outside = 0;
  for (size_t i = 0; i < rows; ++i) {
    const glm::ivec4 c = got[i], t = tt[i];
    const bool empty = c.x > c.y, bruteEmpty = c.z > c.w;
    const bool same = empty ? bruteEmpty : c.x == c.z && c.y == c.w;
    if (!same && ++wrong <= 5)
      ADD_FAILURE() << "triangle " << i / kRows << ", row " << i % kRows << ": columns " << c.x << "-" << c.y
                    << ", pixel by pixel " << c.z << "-" << c.w;
    if (!empty && (c.x < t.x || c.y > t.y) && ++outside <= 5)
      ADD_FAILURE() << "triangle " << i / kRows << ", row " << i % kRows << ": columns " << c.x << "-" << c.y
                    << " past tileTouches' " << t.x << "-" << t.y;
    if (t.z > 0) { EXPECT_EQ(t.z, t.y - t.x + 1) << "row " << i << ": the tiles tileTouches accepts are not one run"; }
    tested += t != glm::ivec4(1, 0, 0, 0);
    listed += empty ? 0 : size_t(c.y - c.x + 1);
    accepted += size_t(t.z);
  }
  std::printf("touched columns: %zu tile rows of %zu triangles, %zu tiles listed (tileTouches: %zu), %zu rows wrong\n", tested,
              tris.size() / 3, listed, accepted, wrong);
  EXPECT_EQ(wrong, 0u);
  EXPECT_EQ(outside, 0u);
  EXPECT_GT(listed, tested) << "too few tiles to test";
}

}  // namespace
}  // namespace rtr
