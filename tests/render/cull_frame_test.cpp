// Culling in the frame (render/raster.hpp with a CullCamera, docs/culling.md): the compute rasteriser's
// frames with two-phase cluster culling, and with the frustum and cone tests alone in one pass, equal those without,
// bit for bit (ids and final image), over a camera path that jumps between views outside and inside the temple and moves in small steps.
#include <cstdio>

#include <gtest/gtest.h>

#include "core/bounds.hpp"
#include "core/camera.hpp"
#include "render/headless.hpp"
#include "scene/load.hpp"
#include "test_paths.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

class CullFrameTest : public test::VulkanTest {};

TEST_F(CullFrameTest, CulledFramesEqualUnculledOnesAlongACameraPath) {
  if (!render::ComputeRaster::supported(*ctx)) GTEST_SKIP() << "no 64-bit buffer atomics";
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  const VkExtent2D e{320, 200};
  const float aspect = float(e.width) / float(e.height);
  // Each renderer keeps its own culling history: one follows the path for ids, one for images, one never culls.
  // And one culls by frustum and cones alone, in one pass.
  render::HeadlessRenderer idsCulled(*ctx, gpu, e), imagesCulled(*ctx, gpu, e), reference(*ctx, gpu, e), single(*ctx, gpu, e);
  render::RenderSettings on, off, frustum;
  on.raster = off.raster = frustum.raster = render::RasterPath::Compute;
  on.mosaic = off.mosaic = frustum.mosaic = render::MosaicMode::Off;
  on.cull = render::Culling::TwoPhase;
  off.cull = render::Culling::Off;
  frustum.cull = render::Culling::Frustum;

  const Bounds b = scene.bounds();
  const CameraPose inside = scene.defaultView.value_or(CameraPose{b.center(), 0, 0});
  std::vector<CameraPose> path = {
      orbitFrame(b, Lens{}, aspect, 200.0f, -5.0f),  // no history yet
      orbitFrame(b, Lens{}, aspect, 200.0f, -5.0f),  // the same again
      orbitFrame(b, Lens{}, aspect, 30.0f, -25.0f),    inside, {inside.position, inside.yawDeg + 120.0f, inside.pitchDeg - 10.0f},
      {inside.position, inside.yawDeg - 70.0f, -60.0f}};
  for (int step = 1; step <= 4; ++step)  // walking and turning, a little each frame
    path.push_back({inside.position + float(step) * glm::vec3(0.3f, 0.0f, 0.4f), inside.yawDeg + 10.0f * step, inside.pitchDeg});
  path.push_back(orbitFrame(b, Lens{}, aspect, 120.0f, -15.0f));

  uint32_t culled[3] = {}, culledSingle[2] = {};
  for (size_t f = 0; f < path.size(); ++f) {
    SCOPED_TRACE(testing::Message() << "frame " << f);
    const Lens lens = fitDepthRange(Lens{}, b, path[f]);
    const std::vector<uint32_t> want = reference.ids(path[f], lens, off), got = idsCulled.ids(path[f], lens, on);
    ASSERT_FALSE(reference.renderer().cullStats(0)) << "culling off counts nothing";
    const auto c = idsCulled.renderer().cullStats(0);
    ASSERT_TRUE(c);
    size_t differ = 0, covered = 0;
    for (size_t i = 0; i < want.size(); ++i) differ += want[i] != got[i], covered += want[i] != VIS_EMPTY;
    EXPECT_EQ(differ, 0u) << "pixels whose id culling changed";
    EXPECT_EQ(imagesCulled.render(path[f], lens, on).image.pixels, reference.render(path[f], lens, off).image.pixels);
    std::printf(
        "culled frame %zu: %u clusters, early %u, late %u more; culled by frustum %u, cone %u, occlusion %u; "
        "%zu px covered\n",
        f, c->clusters, c->early, c->late, c->frustum, c->cone, c->occlusion, covered);
    EXPECT_LE(c->early + c->late + c->frustum + c->cone, c->clusters + c->early) << "counted once per pass";
    EXPECT_LE(c->frustum + c->cone + c->occlusion, c->clusters);
    if (f == 0) { EXPECT_EQ(c->early, 0u) << "no history before the first frame"; }
    if (f == 1) { EXPECT_EQ(c->late, 0u) << "the same view again: the early phase drew all"; }
    culled[0] += c->frustum, culled[1] += c->cone, culled[2] += c->occlusion;
    EXPECT_EQ(single.ids(path[f], lens, frustum), want) << "culled by frustum and cones alone";
    const auto s = single.renderer().cullStats(0);
    ASSERT_TRUE(s);
    EXPECT_EQ(s->early + s->occlusion, 0u) << "one pass, no pyramid";
    culledSingle[0] += s->frustum, culledSingle[1] += s->cone;
  }
  for (uint32_t k = 0; k < 2; ++k) EXPECT_GT(culledSingle[k], 0u) << "one pass, reason " << k;
  // Every test must have culled something along the path, or equal frames prove little.
  for (uint32_t k = 0; k < 3; ++k) EXPECT_GT(culled[k], 0u) << "reason " << k;
}

}  // namespace
}  // namespace rtr
