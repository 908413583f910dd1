// The visibility buffer cleared by the shading pass (docs/raster.md, "The clear left to shading"): a frame
// whose shading pass wrote RASTER_CLEAR back into every word lets the next frame skip the full clear, so each
// frame must still give exactly what a fresh renderer gives for its camera, whatever came before it: other
// views, a resize, a read-back of the ids, a pipeline reload, bench frames, culling (one pass or two), a
// transparency pass reading the ids after shading. References: a fresh renderer per view and size with
// RTR_CLEAR_IN_SHADE=0 (the full clear every frame, as before the fold). Each test runs with the fold
// (RTR_CLEAR_IN_SHADE=1) and without it (=0).
#include <cstdlib>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "test_paths.hpp"

#include "core/image.hpp"
#include "render/headless.hpp"
#include "quads.hpp"
#include "scene/load.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using render::Culling;
using render::MosaicMode;

constexpr Culling kCullings[] = {Culling::Off, Culling::Frustum, Culling::TwoPhase};

// What one camera gives: the ids (HeadlessRenderer::ids) and the images without and with the post pass
// (mosaic off: the shading pass writes the target; compute: the linear image, then the post pass).
struct Views {
  std::vector<uint32_t> ids;
  std::vector<uint8_t> plain, mosaic;
};

// Elements (ids, or bytes of two images) that differ; a size mismatch counts whole.
template <class T>
size_t differing(const std::vector<T>& a, const std::vector<T>& b) {
  size_t n = a.size() == b.size() ? 0 : std::max(a.size(), b.size());
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) n += a[i] != b[i];
  return n;
}

size_t covered(const std::vector<uint32_t>& ids) {
  return size_t(std::count_if(ids.begin(), ids.end(), [](uint32_t id) { return id != VIS_EMPTY; }));
}

// GetParam(): RTR_CLEAR_IN_SHADE for the renderer under test, set while it makes its rasteriser.
class ClearFoldTest : public test::VulkanTest, public testing::WithParamInterface<const char*> {
 protected:
  void SetUp() override {
    VulkanTest::SetUp();
    if (!render::ComputeRaster::supported(*ctx)) GTEST_SKIP() << "no 64-bit buffer atomics";
    ::setenv("RTR_CLEAR_IN_SHADE", GetParam(), 1);  // also for the rasteriser a pipeline reload makes
  }
  bool fold() const { return std::string(GetParam()) == "1"; }
  void TearDown() override {
    ::unsetenv("RTR_CLEAR_IN_SHADE");
    VulkanTest::TearDown();
  }
  static render::RenderSettings settings(MosaicMode mosaic, Culling cull = Culling::Off) {
    render::RenderSettings s;
    s.raster = render::RasterPath::Compute;
    s.mosaic = mosaic;
    s.cull = cull;
    return s;
  }
  // What a fresh renderer with the full clear every frame gives for `pose` at `extent` (once per camera and size).
  const Views& reference(const render::GpuScene& gpu, VkExtent2D extent, const CameraPose& pose, const Lens& lens) {
    const auto key = std::tuple(extent.width, extent.height, pose.position.x, pose.position.y, pose.position.z, pose.yawDeg);
    auto [it, fresh] = references_.try_emplace(key);
    if (fresh) {
      render::HeadlessRenderer r(*ctx, gpu, extent);
      ::setenv("RTR_CLEAR_IN_SHADE", "0", 1);  // read by its first frame, which makes its rasteriser
      it->second.ids = r.ids(pose, lens, settings(MosaicMode::Off));
      ::setenv("RTR_CLEAR_IN_SHADE", GetParam(), 1);
      it->second.plain = r.render(pose, lens, settings(MosaicMode::Off)).image.pixels;
      it->second.mosaic = r.render(pose, lens, settings(MosaicMode::Compute)).image.pixels;
    }
    return it->second;
  }
  std::map<std::tuple<uint32_t, uint32_t, float, float, float, float>, Views> references_;
};

// The default temple: its stored view, outside (rtr-view --camera 0,3,8,0,-15) and inside (0,1.5,0,30,-5),
// one renderer frame after frame, with and without the post pass and culling (off, frustum, two-phase): each frame's image
// and ids equal a fresh renderer's for that camera, through other views, a read-back of the ids (which keeps
// them: the next frame clears in full), a resize (a new buffer) and a pipeline reload (a new rasteriser).
TEST_P(ClearFoldTest, ConsecutiveViewsMatchAFreshRenderer) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  const VkExtent2D small{160, 90}, large{192, 144};
  const CameraPose stored = scene.defaultView.value_or(frameBounds(scene.bounds(), Lens{}, 160.0f / 90.0f));
  const CameraPose views[3] = {stored, {{0, 3, 8}, 0, -15}, {{0, 1.5f, 0}, 30, -5}};
  auto lens = [&](const CameraPose& pose) { return fitDepthRange(Lens{}, scene.bounds(), pose); };
  render::HeadlessRenderer r(*ctx, gpu, small);
  r.render(views[2], lens(views[2]), settings(MosaicMode::Off));
  for (Culling cull : kCullings)
    for (MosaicMode mosaic : {MosaicMode::Off, MosaicMode::Compute}) {
      SCOPED_TRACE(testing::Message() << "--cull " << enumName(cull) << ", mosaic " << enumName(mosaic));
      const render::RenderSettings s = settings(mosaic, cull);
      auto image = [&](VkExtent2D e, int v) {
        SCOPED_TRACE(testing::Message() << "image of view " << v << " at " << e.width << "x" << e.height);
        const Views& want = reference(gpu, e, views[v], lens(views[v]));
        EXPECT_EQ(
            differing(r.render(views[v], lens(views[v]), s).image.pixels, mosaic == MosaicMode::Off ? want.plain : want.mosaic),
            0u)
            << "bytes that differ from a fresh renderer's image";
        EXPECT_EQ(r.renderer().idsCleared(), fold()) << "the shading pass clears the ids where nothing reads them after it";
      };
      auto ids = [&](VkExtent2D e, int v) {
        SCOPED_TRACE(testing::Message() << "ids of view " << v << " at " << e.width << "x" << e.height);
        const Views& want = reference(gpu, e, views[v], lens(views[v]));
        const std::vector<uint32_t> got = r.ids(views[v], lens(views[v]), s);
        EXPECT_FALSE(r.renderer().idsCleared()) << "kept for the read-back";
        EXPECT_EQ(differing(got, want.ids), 0u) << "pixels whose id differs from a fresh renderer's";
        EXPECT_GT(covered(want.ids), size_t(e.width) * e.height / 4);
      };
      image(small, 0);  // after the last frame of the loop before: another view or size
      image(small, 1);
      ids(small, 2);
      image(small, 0);  // after a frame that kept its ids
      ids(small, 1);
      image(small, 2);
      r.resize(large);
      image(large, 1);  // a new buffer
      image(large, 2);
      r.renderer().rebuildPipelines();
      image(large, 0);  // a new rasteriser
      ids(large, 2);
      image(large, 1);
      r.resize(small);
    }
}

// rtr-view --bench's frames (no counters read back) and then ids() of another view: a fresh renderer's ids.
TEST_P(ClearFoldTest, IdsAfterBenchFramesEqualAFreshRenderer) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  const VkExtent2D e{160, 90};
  const CameraPose stored = scene.defaultView.value_or(frameBounds(scene.bounds(), Lens{}, 160.0f / 90.0f));
  const CameraPose outside{{0, 3, 8}, 0, -15};
  const Lens lensStored = fitDepthRange(Lens{}, scene.bounds(), stored),
             lensOutside = fitDepthRange(Lens{}, scene.bounds(), outside);
  render::HeadlessRenderer r(*ctx, gpu, e);
  for (Culling cull : kCullings) {
    SCOPED_TRACE(testing::Message() << "--cull " << enumName(cull));
    render::RenderSettings timed = settings(MosaicMode::Off, cull);
    timed.counters = false;
    r.bench(stored, lensStored, timed, 3);
    EXPECT_EQ(r.renderer().idsCleared(), fold());
    const std::vector<uint32_t> got = r.ids(outside, lensOutside, settings(MosaicMode::Off, cull));
    EXPECT_EQ(differing(got, reference(gpu, e, outside, lensOutside).ids), 0u);
    r.bench(outside, lensOutside, timed, 2);
    EXPECT_EQ(differing(r.ids(stored, lensStored, settings(MosaicMode::Off, cull)), reference(gpu, e, stored, lensStored).ids),
              0u);
  }
}

using test::quad;
using test::unlit;

// A scene with blended surfaces: the transparency pass reads the compute ids after shading (its depth), so
// the shading pass must leave them. Opaque quads at two depths and blended ones between, seen from places
// that put different quads in front: each frame's image and ids are a fresh renderer's.
TEST_P(ClearFoldTest, FramesWithATransparencyPassMatchAFreshRenderer) {
  Scene scene;
  scene.materials = {unlit({0.1f, 0.5f, 0.9f}, 1, false), unlit({0.9f, 0.2f, 0.1f}, 0.4f, true),
                     unlit({0.2f, 0.8f, 0.3f}, 0.7f, true), unlit({0.7f, 0.7f, 0.2f}, 1, false)};
  scene.meshes = {quad(-1.0f, 1.0f, -0.5f, 0.5f, 0.5f, 1), quad(-5, 1.0f, -5, 5, -1.0f, 0), quad(-1.0f, 1.0f, -0.5f, 5, 0.0f, 2),
                  quad(0.3f, 5, 0.1f, 5, 1.0f, 3)};
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  ASSERT_EQ(gpu.blendDraws().size(), 2u);
  Lens lens;
  lens.fovYDeg = 90.0f;
  const CameraPose views[3] = {{{0, 0, 2.0f}, 0, 0}, {{1.5f, 0.5f, 3.0f}, 20, -5}, {{-1.0f, -0.5f, 1.5f}, -25, 10}};
  const VkExtent2D small{64, 64}, large{96, 48};
  render::HeadlessRenderer r(*ctx, gpu, small);
  r.render(views[1], lens, settings(MosaicMode::Off));
  VkExtent2D now = small;
  for (Culling cull : kCullings) {
    SCOPED_TRACE(testing::Message() << "--cull " << enumName(cull));
    const render::RenderSettings s = settings(MosaicMode::Off, cull);
    for (auto [e, v, what] : {std::tuple{small, 0, "image"},
                              {small, 1, "image"},
                              {small, 2, "ids"},
                              {small, 0, "image"},
                              {large, 1, "image"},
                              {large, 2, "image"},
                              {large, 0, "ids"}}) {
      SCOPED_TRACE(testing::Message() << what << " of view " << v << " at " << e.width << "x" << e.height);
      if (e.width != now.width) r.resize(now = e);
      const Views& want = reference(gpu, e, views[v], lens);
      if (std::string(what) == "ids") EXPECT_EQ(differing(r.ids(views[v], lens, s), want.ids), 0u);
      else EXPECT_EQ(differing(r.render(views[v], lens, s).image.pixels, want.plain), 0u) << "bytes that differ";
      EXPECT_FALSE(r.renderer().idsCleared()) << "the transparency pass reads them after shading";
      EXPECT_GT(covered(want.ids), size_t(e.width) * e.height / 8);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Fold, ClearFoldTest, testing::Values("1", "0"),
                         [](const testing::TestParamInfo<const char*>& i) { return std::string(i.param) == "1" ? "On" : "Off"; });

}  // namespace
}  // namespace rtr
