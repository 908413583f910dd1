// The shading pass's IDENTITY variant (vis_shade.comp): where every instance is the identity, no transform
// is applied, and the image is byte for byte the one with the transforms applied (RTR_SHADE_IDENTITY=0),
// though the product with an exact identity turns a -0 coordinate into +0. Scenes nobody here wrote come
// from Debian's assimp-testmodels.
#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

#include "test_paths.hpp"

#include "render/headless.hpp"
#include "core/camera.hpp"
#include "scene/load.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

constexpr uint32_t kW = 320, kH = 180;
const std::filesystem::path kModels = "/usr/share/assimp/models";

class ShadeIdentityTest : public test::VulkanTest {
 protected:
  // The scene's shaded image on the visibility path, `raster`'s ids, with the variant allowed or not.
  ImageRGBA8 shade(const Scene& scene, const render::GpuScene& gpu, const CameraPose& pose, render::RasterPath raster,
                   bool identity) {
    if (identity) ::unsetenv("RTR_SHADE_IDENTITY");
    else ::setenv("RTR_SHADE_IDENTITY", "0", 1);
    render::HeadlessRenderer renderer(*ctx, gpu, VkExtent2D{kW, kH});
    render::RenderSettings s;
    s.shading = render::ShadingPath::Visibility;
    s.raster = raster;
    s.mosaic = render::MosaicMode::Off;
    ImageRGBA8 image = renderer.render(pose, fitDepthRange(Lens{}, scene.bounds(), pose), s, 1).image;  // made here
    ::unsetenv("RTR_SHADE_IDENTITY");
    return image;
  }
  // Both images, on both rasterisers' ids: the same bytes, and enough of them lit to mean something.
  void expectSame(const Scene& scene, const std::vector<CameraPose>& poses) {
    const render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
    for (const CameraPose& pose : poses)
      for (auto raster : {render::RasterPath::Compute, render::RasterPath::Hardware}) {
        SCOPED_TRACE(testing::Message() << enumName(raster) << " raster, pose " << pose.position.x << "," << pose.position.y
                                        << "," << pose.position.z);
        const ImageRGBA8 with = shade(scene, gpu, pose, raster, false), without = shade(scene, gpu, pose, raster, true);
        ASSERT_EQ(with.pixels.size(), without.pixels.size());
        size_t differ = 0, lit = 0;
        for (size_t i = 0; i < with.pixels.size(); i += 4) {
          differ += !std::equal(&with.pixels[i], &with.pixels[i + 4], &without.pixels[i]);
          lit += with.pixels[i] != with.pixels[0] || with.pixels[i + 1] != with.pixels[1];
        }
        EXPECT_EQ(differ, 0u) << "of " << with.pixels.size() / 4 << " pixels";
        EXPECT_GT(lit, size_t(kW) * kH / 50) << "comparing backdrops proves nothing";
      }
  }
};

TEST_F(ShadeIdentityTest, TempleViewsAreTheSameBytes) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  {
    const render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
    EXPECT_TRUE(gpu.identityInstances());
  }
  const CameraPose stored = scene.defaultView.value_or(frameBounds(scene.bounds(), Lens{}, float(kW) / kH));
  expectSame(scene, {stored, CameraPose{{0, 1.5f, 0}, 30, -5}, CameraPose{{0, 3, 8}, 0, -15}});
}

// A textured OBJ (identity) and glTF's BoxTextured, whose node turns the box: not the identity, so the
// transforms stay, and the image with the variant allowed is the same only if the scene says so rightly.
TEST_F(ShadeIdentityTest, ModelsAreTheSameBytes) {
  if (!std::filesystem::exists(kModels)) GTEST_SKIP() << kModels << " missing (Debian's assimp-testmodels)";
  for (const char* file : {"OBJ/spider.obj", "glTF2/BoxTextured-glTF/BoxTextured.gltf"}) {
    SCOPED_TRACE(file);
    const Scene scene = loadScene(kModels / file);
    const render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
    EXPECT_EQ(gpu.identityInstances(), std::string(file).ends_with(".obj"));
    expectSame(scene, {frameBounds(scene.bounds(), Lens{}, float(kW) / kH)});
  }
}

}  // namespace
}  // namespace rtr
