// The compute rasteriser (render/raster.hpp) against the hardware's visibility ids, and on its own: a
// closed mesh seen from inside is covered exactly once per pixel (docs/raster.md).
#include <algorithm>
#include <cstdio>

#include <gtest/gtest.h>

#include "test_paths.hpp"

#include "render/headless.hpp"
#include "scene/load.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using render::RasterPath;

// Where a visibility id's triangle is: its mesh (draws are the meshes with indices, in order) and index.
struct IdDecoder {
  std::vector<const Mesh*> draws;
  uint32_t primitiveBits;
  IdDecoder(const Scene& s, uint32_t bits) : primitiveBits(bits) {
    for (const Mesh& m : s.meshes)
      if (!m.indices.empty()) draws.push_back(&m);
  }
  std::array<glm::vec3, 3> triangle(uint32_t id) const {
    const Mesh& m = *draws.at(id >> primitiveBits);
    const uint32_t t = id & ((1u << primitiveBits) - 1u);
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

class RasterTest : public test::VulkanTest {
 protected:
  void SetUp() override {
    VulkanTest::SetUp();
    if (!render::ComputeRaster::supported(*ctx)) GTEST_SKIP() << "no 64-bit buffer atomics";
  }
  std::vector<uint32_t> ids(render::HeadlessRenderer& r, const CameraPose& pose, const Lens& lens, RasterPath raster) {
    render::RenderSettings s;
    s.raster = raster;
    s.mosaic = render::MosaicMode::Off;
    return r.ids(pose, lens, s);
  }
};

// Same views, both rasterisers: at least 99.9 % of covered pixels carry the same triangle, and every pixel
// that differs has its centre within 1/64 pixel of an edge of one of the two triangles (vertices are snapped
// to 1/256 pixel; a tie on a shared edge or a snapping difference) or is a depth tie (the two triangles'
// planes within 1e-5 in z/w there: where they interpenetrate or nearly coincide), nothing else.
TEST_F(RasterTest, HardwareAndComputeIdsAgree) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  const VkExtent2D extent{320, 180};
  render::HeadlessRenderer r(*ctx, gpu, extent);
  const IdDecoder decode(scene, r.renderer().primitiveBits());
  const CameraPose framed = scene.defaultView.value_or(frameBounds(scene.bounds(), Lens{}, 320.0f / 180.0f));
  const glm::vec3 c = scene.bounds().center();
  // Framed; inside, low, turned (floor and walls cross the near plane); close to a pillar, steep.
  const CameraPose poses[] = {framed, {c + glm::vec3(0, 0.3f, 0), 70.0f, -10.0f}, {c + glm::vec3(2, -0.5f, 1), 200.0f, -35.0f}};
  for (const CameraPose& pose : poses) {
    SCOPED_TRACE(testing::Message() << "pose " << pose.position.x << "," << pose.position.y << "," << pose.position.z);
    Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
    lens.zNear = 0.05f;  // near enough that geometry crosses it
    const std::vector<uint32_t> hw = ids(r, pose, lens, RasterPath::Hardware);
    ASSERT_EQ(r.renderer().rasterFor({}), RasterPath::Compute);
    const std::vector<uint32_t> cs = ids(r, pose, lens, RasterPath::Compute);
    const glm::dmat4 vp = glm::dmat4(projectionMatrix(lens, 320.0f / 180.0f) * viewMatrix(pose));
    size_t covered = 0, same = 0, offEdge = 0;
    for (uint32_t y = 0; y < extent.height; ++y)
      for (uint32_t x = 0; x < extent.width; ++x) {
        const size_t i = size_t(y) * extent.width + x;
        if (hw[i] == VIS_EMPTY && cs[i] == VIS_EMPTY) continue;
        ++covered;
        if (hw[i] == cs[i]) {
          ++same;
          continue;
        }
        double d = 1e30;
        for (uint32_t id : {hw[i], cs[i]})
          if (id != VIS_EMPTY) d = std::min(d, outlineDistance(vp, decode.triangle(id), {320, 180}, {x + 0.5, y + 0.5}));
        // Or a depth tie: the two triangles' planes meet (or nearly coincide) at the pixel centre.
        const double dz = hw[i] == VIS_EMPTY || cs[i] == VIS_EMPTY
                              ? 1.0
                              : std::abs(planeDepth(vp, decode.triangle(hw[i]), {320, 180}, {x + 0.5, y + 0.5}) -
                                         planeDepth(vp, decode.triangle(cs[i]), {320, 180}, {x + 0.5, y + 0.5}));
        if (d > 1.0 / 64 && dz > 1e-5) {
          if (++offEdge < 10) ADD_FAILURE() << "pixel " << x << "," << y << ": hardware " << hw[i] << ", compute " << cs[i]
                                            << ", " << d << " px from the nearest edge, depths " << dz << " apart";
        }
      }
    std::printf("ids: %zu of %zu covered pixels agree (%.4f %%), %zu differing off an edge\n", same, covered,
                100.0 * same / covered, offEdge);
    EXPECT_GT(covered, size_t(extent.width) * extent.height / 4) << "too little drawn to compare";
    EXPECT_GE(double(same), 0.999 * double(covered));
    EXPECT_EQ(offEdge, 0u);
  }
}

}  // namespace
}  // namespace rtr
