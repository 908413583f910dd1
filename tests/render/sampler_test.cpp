// The texture filter and anisotropy (the brief's mip experiments), switched between frames of one renderer.
#include <cstdio>

#include <gtest/gtest.h>

#include "test_paths.hpp"

#include "render/headless.hpp"
#include "scene/load.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using render::RenderSettings;
using render::TextureFilter;

constexpr uint32_t kW = 320, kH = 180;

class SamplerTest : public test::VulkanTest {
 protected:
  void SetUp() override {
    VulkanTest::SetUp();
    scene = loadScene(test::assetDir() / "temple.rtrscene");
    gpu = std::make_unique<render::GpuScene>(*ctx, scene, render::MipMode::Compute);
    renderer = std::make_unique<render::HeadlessRenderer>(*ctx, *gpu, VkExtent2D{kW, kH});
    pose = *scene.defaultView;
    lens = fitDepthRange(Lens{}, scene.bounds(), pose);
  }
  void TearDown() override {
    renderer.reset();
    gpu.reset();
    VulkanTest::TearDown();
  }
  ImageRGBA8 render(int mode, TextureFilter filter, render::ShadingPath path = render::ShadingPath::Visibility,
                    float anisotropy = 1.0f, float lodBias = 0.0f) {
    RenderSettings s;
    s.mode = mode;
    s.shading = path;
    s.mosaic = render::MosaicMode::Off;
    s.lodBias = lodBias;
    s.sampler = {filter, anisotropy};
    return renderer->render(pose, lens, s).image;
  }
  Scene scene;
  std::unique_ptr<render::GpuScene> gpu;
  std::unique_ptr<render::HeadlessRenderer> renderer;
  CameraPose pose;
  Lens lens;
};

size_t differingPixels(const ImageRGBA8& a, const ImageRGBA8& b) {
  size_t n = 0;
  for (size_t i = 0; i < a.pixels.size(); i += 4)
    n += a.pixels[i] != b.pixels[i] || a.pixels[i + 1] != b.pixels[i + 1] || a.pixels[i + 2] != b.pixels[i + 2];
  return n;
}

// Pixels of the mip view whose colour is not one whole level's: the level colours (and the grey of
// untextured surfaces, the black background) have only 0, 0.5 and 1 as channels, 8-bit 0, 127/128, 255.
size_t blendedPixels(const ImageRGBA8& img) {
  size_t n = 0;
  auto whole = [](uint8_t c) { return c == 0 || c == 127 || c == 128 || c == 255; };
  for (size_t i = 0; i < img.pixels.size(); i += 4)
    n += !(whole(img.pixels[i]) && whole(img.pixels[i + 1]) && whole(img.pixels[i + 2]));
  return n;
}

TEST_F(SamplerTest, NearestMipViewShowsOnlyWholeLevels) {
  const ImageRGBA8 trilinear = render(VIEW_MIP_LEVEL, TextureFilter::Trilinear);
  const ImageRGBA8 nearestMip = render(VIEW_MIP_LEVEL, TextureFilter::NearestMip);
  EXPECT_GT(blendedPixels(trilinear), size_t(kW * kH / 10));  // the floor blends levels
  EXPECT_EQ(blendedPixels(nearestMip), 0u);
  // With a bias the nearest level moves, still whole.
  const ImageRGBA8 biased = render(VIEW_MIP_LEVEL, TextureFilter::NearestMip, render::ShadingPath::Forward, 1.0f, 1.5f);
  EXPECT_EQ(blendedPixels(biased), 0u);
  EXPECT_GT(differingPixels(biased, nearestMip), size_t(kW * kH / 10));
}

TEST_F(SamplerTest, FilterChangesTheShadedViewOnBothPathsAndSwitchesBack) {
  for (auto path : {render::ShadingPath::Visibility, render::ShadingPath::Forward}) {
    SCOPED_TRACE(rtr::enumName(path));
    const ImageRGBA8 trilinear = render(VIEW_SHADED, TextureFilter::Trilinear, path);
    const ImageRGBA8 nearestMip = render(VIEW_SHADED, TextureFilter::NearestMip, path);
    const ImageRGBA8 nearest = render(VIEW_SHADED, TextureFilter::Nearest, path);
    EXPECT_GT(differingPixels(trilinear, nearestMip), size_t(kW * kH / 20));
    EXPECT_GT(differingPixels(nearestMip, nearest), size_t(kW * kH / 20));
    // The descriptors were rewritten, not added to: back to trilinear is the first frame again.
    EXPECT_EQ(differingPixels(trilinear, render(VIEW_SHADED, TextureFilter::Trilinear, path)), 0u);
  }
}

// --filter reaches every pipeline that samples the scene's textures (they share one writer): the
// forward image (through either mosaic pass, compute or graphics) and the visibility images change with it
// on both rasterisers, and so do the compute rasteriser's ids, whose alpha-masked foliage its hardware
// hand-off tests with the same sampler as the others (so its coverage stays the hardware rasteriser's).
TEST_F(SamplerTest, FilterNearestChangesEveryPath) {
  struct Path {
    render::ShadingPath shading;
    render::RasterPath raster;
    render::MosaicMode mosaic = render::MosaicMode::Off;
  };
  std::vector<Path> paths = {{render::ShadingPath::Forward, render::RasterPath::Auto},
                             {render::ShadingPath::Forward, render::RasterPath::Auto, render::MosaicMode::Graphics},
                             {render::ShadingPath::Visibility, render::RasterPath::Hardware}};
  const bool compute = render::ComputeRaster::supported(*ctx);
  if (compute) paths.push_back({render::ShadingPath::Visibility, render::RasterPath::Compute, render::MosaicMode::Compute});
  std::vector<uint32_t> ids[2][2];  // [raster hardware, compute][trilinear, nearest]
  for (const Path& p : paths)
    for (int nearest = 0; nearest < 2; ++nearest) {
      RenderSettings s;
      s.shading = p.shading;
      s.raster = p.raster;
      s.mosaic = p.mosaic;
      s.sampler.filter = nearest ? TextureFilter::Nearest : TextureFilter::Trilinear;
      if (p.shading == render::ShadingPath::Visibility)
        ids[p.raster == render::RasterPath::Compute][nearest] = renderer->ids(pose, lens, s);
      if (nearest) continue;
      SCOPED_TRACE(testing::Message() << enumName(p.shading) << ", " << enumName(p.raster) << ", mosaic " << enumName(p.mosaic));
      const ImageRGBA8 a = renderer->render(pose, lens, s).image;
      s.sampler.filter = TextureFilter::Nearest;
      EXPECT_GT(differingPixels(a, renderer->render(pose, lens, s).image), size_t(kW * kH / 20));
    }
  if (!compute) return;
  size_t moved = 0, disagree = 0;
  for (size_t i = 0; i < ids[1][0].size(); ++i) {
    moved += ids[1][0][i] != ids[1][1][i];
    disagree += ids[0][1][i] != ids[1][1][i];
  }
  EXPECT_GT(moved, 50u) << "the compute rasteriser's alpha test ignored the filter";
  EXPECT_LT(disagree, moved / 4) << "compute and hardware ids under the nearest filter";
  std::printf("nearest filter: %zu compute ids moved, %zu differ from the hardware's\n", moved, disagree);
}

TEST_F(SamplerTest, AnisotropyChangesTheShadedViewWhereSupported) {
  if (render::maxAnisotropy(*ctx) < 2) GTEST_SKIP() << "no samplerAnisotropy";
  const ImageRGBA8 off = render(VIEW_SHADED, TextureFilter::Trilinear);
  const ImageRGBA8 on = render(VIEW_SHADED, TextureFilter::Trilinear, render::ShadingPath::Visibility, 16.0f);
  // lavapipe filters anisotropically only where the footprint is long (the far floor): a few hundred pixels.
  EXPECT_GT(differingPixels(off, on), size_t(kW * kH / 1000));
  // More than the device offers is clamped, not an error (validation checks the sampler).
  EXPECT_EQ(differingPixels(
                render(VIEW_SHADED, TextureFilter::Trilinear, render::ShadingPath::Visibility, render::maxAnisotropy(*ctx) * 4),
                render(VIEW_SHADED, TextureFilter::Trilinear, render::ShadingPath::Visibility, render::maxAnisotropy(*ctx))),
            0u);
}

}  // namespace
}  // namespace rtr
