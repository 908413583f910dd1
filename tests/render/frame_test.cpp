// Whole frames rendered headless on lavapipe, checked by properties the images must have.
#include <cmath>

#include <gtest/gtest.h>

#include "core/image.hpp"
#include "render/headless.hpp"
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
    scene = loadScene(std::filesystem::path(RTR_BINARY_DIR) / "assets/temple.rtrscene");
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
  render::HeadlessFrame render(int mode, bool readColor = false) {
    RenderSettings s;
    s.mode = mode;
    s.mosaic = render::MosaicMode::Off;
    return renderer->render(pose, lens, s, 1, readColor);
  }
  Scene scene;
  std::unique_ptr<render::GpuScene> gpu;
  std::unique_ptr<HeadlessRenderer> renderer;
  CameraPose pose;
  Lens lens;
};

TEST_F(FrameTest, ShadedFrameIsFiniteAndLit) {
  auto f = render(VIEW_SHADED, true);
  ASSERT_EQ(f.sceneColor.pixels.size(), size_t(kW) * kH);
  double sum = 0;
  for (const glm::vec4& p : f.sceneColor.pixels) {
    for (int c = 0; c < 4; ++c) ASSERT_TRUE(std::isfinite(p[c])) << "NaN/inf in the intermediate image";
    for (int c = 0; c < 3; ++c) ASSERT_GE(p[c], 0.0f);
    sum += p.r + p.g + p.b;
  }
  EXPECT_GT(sum / (3.0 * kW * kH), 0.01) << "the shaded frame is (nearly) black";
  EXPECT_EQ(f.gpuTimes.size(), 2u);
  EXPECT_GT(gpu->stats().meshes16, 0u) << "small meshes should use 16-bit indices";
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
    auto f = render(mode);
    uint64_t sum = 0;
    for (uint8_t b : f.image.pixels) sum += b;
    EXPECT_GT(sum, 0u) << "mode " << mode << " rendered black";
  }
}

}  // namespace
}  // namespace rtr
