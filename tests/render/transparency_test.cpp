// glTF BLEND on the GPU (render/transparency.cpp): blended quads composite "over" what lies behind them,
// farthest first, whatever their order in the scene; opaque depth hides them; they write no visibility id.
// Unlit materials, so every expected pixel follows from the blending formula alone:
// c = a C + (1 - a) behind. The same in the forward path and the visibility path on both rasterisers.
#include <cmath>

#include <gtest/gtest.h>

#include "core/image.hpp"
#include "render/environment_maps.hpp"
#include "render/headless.hpp"
#include "render/transparency.hpp"
#include "quads.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

constexpr uint32_t kSize = 64;

using test::quad;
using test::unlit;

using test::VulkanTest;

TEST_F(VulkanTest, BlendedQuadsCompositeFarthestFirstInEveryPath) {
  const glm::vec3 back(0.1f, 0.5f, 0.9f), near(0.9f, 0.2f, 0.1f), far(0.2f, 0.8f, 0.3f), block(0.7f, 0.7f, 0.2f);
  const float aNear = 0.4f, aFar = 0.7f;
  Scene scene;
  scene.materials = {unlit(back, 1, false), unlit(near, aNear, true), unlit(far, aFar, true), unlit(block, 1, false)};
  // Seen from +z: the background at z = -1 over the left 3/4 of the view; the near blended quad (listed
  // first, so the scene's order is the wrong one) over the middle band, the far one over the top 3/4;
  // an opaque block in front of both at the right.
  scene.meshes = {quad(-1.0f, 1.0f, -0.5f, 0.5f, 0.5f, 1), quad(-5, 1.0f, -5, 5, -1.0f, 0), quad(-1.0f, 1.0f, -0.5f, 5, 0.0f, 2),
                  quad(0.3f, 5, 0.1f, 5, 1.0f, 3)};
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  ASSERT_EQ(gpu.blendDraws().size(), 2u);
  render::HeadlessRenderer r(*ctx, gpu, {kSize, kSize});
  render::RenderSettings s;
  s.mosaic = render::MosaicMode::Off;
  Lens lens;
  lens.fovYDeg = 90.0f;
  const CameraPose pose{{0, 0, 2.0f}, 0.0f, 0.0f};
  const auto over = [](glm::vec3 c, float a, glm::vec3 behind) { return a * c + (1.0f - a) * behind; };
  // Points of the z = 0 plane to pixels (distance 2, 90°: ±2 fills the view; y down in the image).
  const auto at = [&](const ImageRGBA8& img, float x, float y) {
    return img.at(uint32_t((0.5f + x / 4.0f) * kSize), uint32_t((0.5f - y / 4.0f) * kSize));
  };
  const glm::vec3 black(0.0f);
  struct Probe {
    float x, y;
    glm::vec3 want;
    const char* what;
  };
  const Probe probes[] = {
      {-0.5f, 0.0f, over(near, aNear, over(far, aFar, back)), "near over far over the background"},
      {-0.5f, 1.0f, over(far, aFar, back), "far over the background"},
      {-0.5f, -1.0f, back, "the background alone"},
      {0.5f, -0.6f, over(near, aNear, back), "near over the background (far ends at y -0.5)"},
      {1.4f, -0.25f, black, "nothing"},
      {0.8f, 0.4f, block, "the opaque block hides both"},
  };
  for (auto [path, raster] : {std::pair{render::ShadingPath::Forward, render::RasterPath::Auto},
                              {render::ShadingPath::Visibility, render::RasterPath::Hardware},
                              {render::ShadingPath::Visibility, render::RasterPath::Compute}}) {
    SCOPED_TRACE(testing::Message() << enumName(path) << ", " << enumName(raster));
    s.shading = path;
    s.raster = raster;
    const ImageRGBA8 img = r.render(pose, lens, s).image;
    for (const Probe& p : probes) {
      const uint8_t* px = at(img, p.x, p.y);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(px[c], std::lround(linearToSrgb(p.want[c]) * 255.0f), 1) << p.what << ", channel " << c;
    }
  }
}

// With an environment, blended surfaces get its light as the opaque ones do (the pass's HAS_ENV variant):
// a white half-transparent quad, lit by nothing but uniform radiance 1, over an unlit grey 0.2. Without the
// environment's term the quad adds nothing (c = 0.5 · 0 + 0.5 · 0.2); with it, it reflects its albedo
// (about 1 at normal view in the white furnace), so c ≈ 0.5 · 1 + 0.5 · 0.2 = 0.6.
TEST_F(VulkanTest, BlendedSurfacesAreLitByTheEnvironment) {
  Scene scene;
  Material white;
  white.flags = kMaterialGltf | kMaterialBlend;
  white.baseColor = glm::vec3(1.0f);
  white.opacity = 0.5f;
  white.roughness = 0.5f;
  scene.materials = {unlit(glm::vec3(0.2f), 1, false), white};
  scene.meshes = {quad(-5, 5, -5, 5, -1.0f, 0), quad(-1.0f, 1.0f, -1.0f, 1.0f, 0.0f, 1)};
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  render::HeadlessRenderer r(*ctx, gpu, {kSize, kSize});
  ImageF uniform{64, 32, std::vector<glm::vec4>(64 * 32, glm::vec4(1.0f))};
  r.renderer().setEnvironment(std::make_shared<const render::EnvironmentMaps>(*ctx, Environment(std::move(uniform), 1.0f, 0.0f)));
  render::RenderSettings s;
  s.mosaic = render::MosaicMode::Off;
  s.lights = {};  // no light, no ambient: only the environment
  Lens lens;
  lens.fovYDeg = 90.0f;
  for (auto [path, raster] : {std::pair{render::ShadingPath::Forward, render::RasterPath::Auto},
                              {render::ShadingPath::Visibility, render::RasterPath::Compute}}) {
    SCOPED_TRACE(testing::Message() << enumName(path) << ", " << enumName(raster));
    s.shading = path;
    s.raster = raster;
    const ImageRGBA8 img = r.render(CameraPose{{0, 0, 2.0f}, 0.0f, 0.0f}, lens, s).image;
    const float centre = srgbToLinear(img.at(kSize / 2, kSize / 2)[1] / 255.0f);
    const float outside = srgbToLinear(img.at(2, 2)[1] / 255.0f);
    EXPECT_NEAR(outside, 0.2f, 0.01f) << "the unlit grey behind";
    EXPECT_GT(centre, 0.45f) << "the quad reflects the environment (0.1 would be no light at all)";
    EXPECT_LT(centre, 0.65f);
  }
}

TEST(Transparency, FarthestFirstSortsByDistanceToTheEye) {
  std::vector<render::BlendDraw> draws(3);
  draws[0].item.center = {0, 0, 1}, draws[1].item.center = {0, 0, -5}, draws[2].item.center = {0, 0, -2};
  const auto order = render::farthestFirst(draws, glm::vec3(0, 0, 2));
  ASSERT_EQ(order.size(), 3u);
  EXPECT_EQ(order[0], &draws[1]);
  EXPECT_EQ(order[1], &draws[2]);
  EXPECT_EQ(order[2], &draws[0]);
}

}  // namespace
}  // namespace rtr
