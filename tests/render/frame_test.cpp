// Whole frames rendered headless on lavapipe, checked by properties the images must have.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "test_paths.hpp"

#include "core/image.hpp"
#include "render/environment_maps.hpp"
#include "render/headless.hpp"
#include "vk/image_state.hpp"
#include "scene/load.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using render::HeadlessRenderer;
using render::RenderSettings;

constexpr uint32_t kW = 320, kH = 180;

class FrameTest : public test::VulkanTest {
 protected:
  void SetUp() override {
    VulkanTest::SetUp();
    scene = loadScene(test::assetDir() / "temple.rtrscene");
    gpu = std::make_unique<render::GpuScene>(*ctx, scene, render::MipMode::Compute);
    renderer = std::make_unique<HeadlessRenderer>(*ctx, *gpu, VkExtent2D{kW, kH});
    pose = scene.defaultView.value_or(frameBounds(scene.bounds(), Lens{}, float(kW) / kH));
    lens = fitDepthRange(Lens{}, scene.bounds(), pose);
  }
  void TearDown() override {
    renderer.reset();
    gpu.reset();
    VulkanTest::TearDown();
  }
  render::HeadlessFrame render(int mode, bool readColor = false, render::ShadingPath path = render::ShadingPath::Visibility,
                               float lodBias = 0.0f, render::RasterPath raster = render::RasterPath::Auto) {
    RenderSettings s;
    s.raster = raster;
    s.mode = mode;
    s.shading = path;
    s.lodBias = lodBias;
    s.mosaic = render::MosaicMode::Off;
    return renderer->render(pose, lens, s, 1, readColor);
  }
  Scene scene;
  std::unique_ptr<render::GpuScene> gpu;
  std::unique_ptr<HeadlessRenderer> renderer;
  CameraPose pose;
  Lens lens;
};

bool ranPass(const render::HeadlessFrame& f, const std::string& name) {
  for (const auto& [pass, ms] : f.gpuTimes)
    if (pass == name) return true;
  return false;
}

TEST_F(FrameTest, ShadedFrameIsFiniteAndLit) {
  for (auto path : {render::ShadingPath::Forward, render::ShadingPath::Visibility}) {
    SCOPED_TRACE(rtr::enumName(path));
    auto f = render(VIEW_SHADED, true, path);
    ASSERT_EQ(f.sceneColor.pixels.size(), size_t(kW) * kH);
    double sum = 0;
    for (const glm::vec4& p : f.sceneColor.pixels) {
      for (int c = 0; c < 4; ++c) ASSERT_TRUE(std::isfinite(p[c])) << "NaN/inf in the intermediate image";
      for (int c = 0; c < 3; ++c) ASSERT_GE(p[c], 0.0f);
      sum += p.r + p.g + p.b;
    }
    EXPECT_GT(sum / (3.0 * kW * kH), 0.01) << "the shaded frame is (nearly) black";
    const bool vis = path == render::ShadingPath::Visibility;
    // Hardware ids: visibility, shade, post; compute: clear, raster, raster large, raster hw, shade, post;
    // with culling also cull early, raster early, raster large early, pyramid, cull; with clipping in
    // compute raster clip (and raster clip early).
    const render::RenderSettings defaults;
    const bool compute = renderer->renderer().rasterFor(defaults) == render::RasterPath::Compute;
    const bool twoPhase = defaults.cull == render::Culling::TwoPhase, onePass = defaults.cull == render::Culling::Frustum;
    const size_t clip = defaults.clip ? (twoPhase ? 2u : 1u) : 0u;
    EXPECT_EQ(f.gpuTimes.size(), !vis ? 2u : !compute ? 3u : (twoPhase ? 11u : onePass ? 7u : 6u) + clip);
    EXPECT_EQ(ranPass(f, "shade"), vis);
  }
  EXPECT_GT(gpu->stats().meshes16, 0u) << "small meshes should use 16-bit indices";
}

// Scene draws go nearest first, by their meshes' box centres, so that the depth test rejects hidden
// fragments before shading; ties keep the scene's order.
TEST_F(FrameTest, DrawsGoNearestFirst) {
  const auto& draws = gpu->draws(render::DrawKind::Opaque);
  ASSERT_GE(draws.size(), 3u);
  const auto order = render::nearestFirst(draws, pose.position);
  ASSERT_EQ(order.size(), draws.size());
  auto dist = [&](const render::DrawItem* d) { return glm::length(d->center - pose.position); };
  for (size_t i = 1; i < order.size(); ++i) EXPECT_LE(dist(order[i - 1]), dist(order[i])) << "draw " << i;
  EXPECT_NE(order.front(), &draws.front()) << "the temple's first mesh (the floor) is not the nearest";
  // The centres are the meshes' own: the nearest draw is the one whose mesh's box centre is nearest.
  float nearest = 1e30f;
  for (const Mesh& m : scene.meshes)
    if (!m.indices.empty() && m.material == order.front()->material)
      nearest = std::min(nearest, glm::length(m.bounds.center() - pose.position));
  EXPECT_FLOAT_EQ(dist(order.front()), nearest);
  // Equal distances keep their order.
  std::vector<render::DrawItem> tied(3);
  for (uint32_t i = 0; i < 3; ++i) tied[i].id = i, tied[i].center = glm::vec3(1, 0, 0);
  const auto t = render::nearestFirst(tied, glm::vec3(0));
  EXPECT_TRUE(t[0]->id == 0 && t[1]->id == 1 && t[2]->id == 2);
}

// The visibility path (ids rasterised, BRDF in compute, LOD from analytic texcoord differences) and the
// forward path (BRDF per fragment, LOD from the rasteriser's derivatives) show the same image: same
// coverage, same BRDF; only the rounding of the interpolation and of the LOD differ. Tolerance
// (docs/shading.md): displayed 8-bit values within 3 on at least 99.5 % of pixels and within 24 on all.
// The compute rasteriser's ids differ from the hardware's on a few edge pixels (tests/render/raster_test.cpp),
// where another triangle (or the background) shows: the bound on all pixels holds for hardware ids only.
TEST_F(FrameTest, VisibilityPathMatchesForward) {
  for (auto raster : {render::RasterPath::Hardware, render::RasterPath::Compute})
    for (float bias : {0.0f, 1.5f}) {
      SCOPED_TRACE(testing::Message() << "LOD bias " << bias << ", " << rtr::enumName(raster) << " raster");
      auto fwd = render(VIEW_SHADED, false, render::ShadingPath::Forward, bias);
      auto vis = render(VIEW_SHADED, false, render::ShadingPath::Visibility, bias, raster);
      ASSERT_TRUE(ranPass(vis, "shade") && !ranPass(fwd, "shade"));
      size_t over = 0, lit = 0;
      int worst = 0;
      for (size_t i = 0; i < fwd.image.pixels.size(); i += 4) {
        int d = 0;
        for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(fwd.image.pixels[i + c]) - int(vis.image.pixels[i + c])));
        worst = std::max(worst, d);
        over += d > 3;
        lit += fwd.image.pixels[i] + fwd.image.pixels[i + 1] + fwd.image.pixels[i + 2] > 0;
      }
      const size_t n = fwd.image.pixels.size() / 4;
      std::printf("bias %.1f: %zu of %zu pixels differ by more than 3, worst %d\n", bias, over, n, worst);
      EXPECT_GT(lit, n / 2) << "comparing mostly black images proves nothing";
      EXPECT_LE(over, n / 200);
      if (raster == render::RasterPath::Hardware) { EXPECT_LE(worst, 24); }
    }
}

// With the mosaic off the post pass would only copy the linear image into the target, sRGB-encoded, so
// the shading pass writes those bytes itself and the pass is not recorded; a caller reading the linear
// image gets it and the post pass as before. The bytes are the same: the shading pass encodes the half
// float the image would hold.
TEST_F(FrameTest, ShadingWritesTheBytesThePostPassWould) {
  for (auto raster : {render::RasterPath::Hardware, render::RasterPath::Compute}) {
    SCOPED_TRACE(rtr::enumName(raster));
    const auto direct = render(VIEW_SHADED, false, render::ShadingPath::Visibility, 0.0f, raster);
    const auto copied = render(VIEW_SHADED, true, render::ShadingPath::Visibility, 0.0f, raster);
    EXPECT_TRUE(ranPass(direct, "shade") && !ranPass(direct, "post"));
    EXPECT_TRUE(ranPass(copied, "shade") && ranPass(copied, "post"));
    ASSERT_EQ(direct.image.pixels.size(), copied.image.pixels.size());
    size_t differ = 0, lit = 0;
    for (size_t i = 0; i < direct.image.pixels.size(); i += 4) {
      differ += !std::equal(&direct.image.pixels[i], &direct.image.pixels[i + 4], &copied.image.pixels[i]);
      lit += direct.image.pixels[i] + direct.image.pixels[i + 1] + direct.image.pixels[i + 2] > 0;
    }
    EXPECT_EQ(differ, 0u) << "of " << direct.image.pixels.size() / 4 << " pixels";
    EXPECT_GT(lit, size_t(kW) * kH / 2) << "comparing mostly black images proves nothing";
  }
}

// Along the image's centre column, the bottom 35% is floor: linear depth grows toward the horizon.
TEST_F(FrameTest, LinearDepthGrowsAlongTheFloor) {
  auto f = render(VIEW_LINEAR_DEPTH);
  int prev = -1, rising = 0;
  for (uint32_t y = kH - 1; y > kH * 65 / 100; --y) {
    int v = f.image.at(kW / 2, y)[0];
    EXPECT_GE(v, prev - 1) << "depth decreased at row " << y;
    rising += v > prev;
    prev = std::max(prev, v);
  }
  EXPECT_GT(rising, 5);
}

// Mip level colours run blue (0) -> cyan -> green -> yellow: farther floor is less blue, more red.
TEST_F(FrameTest, MipLevelRisesTowardTheHorizon) {
  auto f = render(VIEW_MIP_LEVEL);
  const uint8_t* near = f.image.at(kW / 2, kH - 2);
  const uint8_t* far = f.image.at(kW / 2, kH * 66 / 100);
  EXPECT_GT(int(near[2]) - int(near[0]), int(far[2]) - int(far[0]));
  EXPECT_GT(int(far[0]) + int(far[1]), int(near[0]) + int(near[1]));
}

TEST_F(FrameTest, DepthDerivativesAreNonZeroOnTheSlantedFloor) {
  auto f = render(VIEW_DEPTH_DERIVATIVES);
  int nonZero = 0;
  for (uint32_t x = 0; x < kW; x += 8) nonZero += f.image.at(x, kH - 10)[1] > 0;
  EXPECT_GT(nonZero, int(kW / 8) * 3 / 4);
}

TEST_F(FrameTest, EveryViewModeRendersWithoutValidationMessages) {
  for (int mode = 1; mode <= VIEW_COUNT; ++mode) {
    // The environment's views show its terms: black without one (environment_shading_test.cpp).
    const bool env = mode == VIEW_ENV_DIFFUSE || mode == VIEW_ENV_SPECULAR;
    if (env) {
      SkySettings sky;
      sky.width = 256;
      sky.height = 128;
      renderer->renderer().setEnvironment(
          std::make_shared<const render::EnvironmentMaps>(*ctx, Environment(makeSky(sky), 1.0f, 0.0f)));
    }
    auto f = render(mode);
    if (env) renderer->renderer().setEnvironment(nullptr);
    uint64_t sum = 0;
    for (uint8_t b : f.image.pixels) sum += b;
    EXPECT_GT(sum, 0u) << "mode " << mode << " rendered black";
  }
}

// The barriers of one steady-state frame (the frame before it read the target back, as this one does),
// written down from what each pass does:
//   the scene pass discards its colour (or id) target after the previous frame's reader, and the depth;
//   [visibility] the ids go to the shading compute pass, which discards the colour image and writes it;
//   the colour image is sampled by the post pass (compute, or fragment for the graphics mosaic), which
//   discards the target after last frame's read-back copy; the target goes to the read-back copy.
//   [visibility, mosaic off] the shading pass discards and writes the target itself: no colour image.
//   The compute rasteriser's buffers are synchronised by memory barriers, which the log does not list: its
//   frame starts at the shading pass, with cluster culling (its pyramid stays in GENERAL) or without.
std::vector<std::string> steadyFrameBarriers(render::ShadingPath path, render::MosaicMode mosaic, bool computeIds) {
  const bool vis = path == render::ShadingPath::Visibility, raster = mosaic == render::MosaicMode::Graphics;
  const std::string postRead = raster ? "FRAGMENT_SHADER" : "COMPUTE_SHADER";
  const std::string first = vis ? "visibility" : "scene colour";
  const std::string firstReader = vis ? "COMPUTE_SHADER" : postRead;
  std::vector<std::string> out = {
      first + ": UNDEFINED -> COLOR_ATTACHMENT, " + firstReader + "/NONE -> COLOR_ATTACHMENT_OUTPUT/COLOR_ATTACHMENT_WRITE",
      "scene depth: UNDEFINED -> DEPTH_ATTACHMENT, EARLY_FRAGMENT_TESTS|LATE_FRAGMENT_TESTS/DEPTH_STENCIL_ATTACHMENT_WRITE"
      " -> EARLY_FRAGMENT_TESTS|LATE_FRAGMENT_TESTS/DEPTH_STENCIL_ATTACHMENT_WRITE"};
  if (vis && computeIds) out.clear();
  if (vis) {
    if (!computeIds)
      out.push_back(
          "visibility: COLOR_ATTACHMENT -> SHADER_READ_ONLY, COLOR_ATTACHMENT_OUTPUT/COLOR_ATTACHMENT_WRITE -> "
          "COMPUTE_SHADER/SHADER_SAMPLED_READ");
    if (mosaic != render::MosaicMode::Off) {
      out.push_back("scene colour: UNDEFINED -> GENERAL, " + postRead + "/NONE -> COMPUTE_SHADER/SHADER_STORAGE_WRITE");
      out.push_back("scene colour: GENERAL -> SHADER_READ_ONLY, COMPUTE_SHADER/SHADER_STORAGE_WRITE -> " + postRead +
                    "/SHADER_SAMPLED_READ");
    }
  } else {
    out.push_back("scene colour: COLOR_ATTACHMENT -> SHADER_READ_ONLY, COLOR_ATTACHMENT_OUTPUT/COLOR_ATTACHMENT_WRITE -> " +
                  postRead + "/SHADER_SAMPLED_READ");
  }
  const std::string work = raster ? "COLOR_ATTACHMENT" : "GENERAL";
  const std::string write = raster ? "COLOR_ATTACHMENT_OUTPUT/COLOR_ATTACHMENT_WRITE" : "COMPUTE_SHADER/SHADER_STORAGE_WRITE";
  out.push_back("headless target: UNDEFINED -> " + work + ", COPY/NONE -> " + write);
  out.push_back("headless target: " + work + " -> TRANSFER_SRC, " + write + " -> COPY/TRANSFER_READ");
  return out;
}

TEST_F(FrameTest, OneFrameRecordsExactlyTheBarriersItNeeds) {
  for (auto path : {render::ShadingPath::Forward, render::ShadingPath::Visibility})
    for (auto raster : {render::RasterPath::Hardware, render::RasterPath::Compute})
      for (auto mosaic : {render::MosaicMode::Off, render::MosaicMode::Compute, render::MosaicMode::Graphics})
        for (auto cull : {render::Culling::TwoPhase, render::Culling::Frustum, render::Culling::Off}) {
          SCOPED_TRACE(std::string(rtr::enumName(path)) + ", mosaic " + rtr::enumName(mosaic) + ", " + rtr::enumName(raster) +
                       " raster, cull " + rtr::enumName(cull));
          RenderSettings s;
          s.cull = cull;
          s.shading = path;
          s.mosaic = mosaic;
          s.raster = raster;
          renderer->render(pose, lens, s);  // the previous frame, read back like the next
          vk::beginBarrierLog();
          renderer->render(pose, lens, s);
          const std::vector<std::string> got = vk::endBarrierLog();
          const std::vector<std::string> want = steadyFrameBarriers(path, mosaic, raster == render::RasterPath::Compute);
          EXPECT_EQ(got.size(), want.size());
          for (size_t i = 0; i < std::max(got.size(), want.size()); ++i)
            EXPECT_EQ(i < got.size() ? got[i] : "(none)", i < want.size() ? want[i] : "(none)") << "barrier " << i;
        }
}

}  // namespace
}  // namespace rtr
