// Textures baked into an .rtrscene (version 6, TEXS) reach the GPU with no decode and no mip pass, and
// draw what the image path draws: level 0 is the same bytes, and each lower level is the float64
// reference filter's (core/mip_reference.hpp) where the image path's GPU or CPU chain is within 1 LSB of
// that same reference per level (mips_test), so frames differ by at most a few LSB where minified texels
// are blended by trilinear filtering and shading (the bound AutoMipsMakeSmallTexturesChainsOnTheCpu uses).
#include <gtest/gtest.h>

#include "bake.hpp"
#include "core/image.hpp"
#include "render/headless.hpp"
#include "scene/baked_texels.hpp"
#include "scene/load.hpp"
#include "scene/rtrscene.hpp"
#include "scene/textures.hpp"
#include "vk/pipeline_cache.hpp"
#include "test_paths.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using test::VulkanTest;
constexpr uint32_t kW = 320, kH = 180;

render::RenderSettings settings(int mode) {
  render::RenderSettings s;
  s.mode = mode;
  s.shading = render::ShadingPath::Forward;
  s.mosaic = render::MosaicMode::Off;
  return s;
}

// The temple with every texture baked as rtr-bake --textures lossless bakes it, through the file format.
Scene bakedTemple(const Scene& files) {
  Scene s = files;
  for (Texture& t : s.textures) {
    const TexelData level0 = decodeTexture(files, t);
    t.baked = packBakedTexels(level0.channels == 1 ? BakedFormat::R8 : BakedFormat::Rgba8, level0.width, level0.height,
                              referenceChain(level0, decodeSrgb(t)));
  }
  const std::string bytes = encodeRtrScene(s);
  return decodeRtrScene({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()}, "baked.rtrscene");
}

TEST_F(VulkanTest, BakedTexturesDrawWhatTheImagePathDraws) {
  const Scene files = loadScene(test::assetDir() / "temple.rtrscene");
  const Scene baked = bakedTemple(files);
  const CameraPose pose = *files.defaultView;
  const Lens lens = fitDepthRange(Lens{}, files.bounds(), pose);
  const uint32_t before = ctx->pipelineCache().stats().created;
  const render::GpuScene b(*ctx, baked, render::MipMode::Compute);
  EXPECT_EQ(ctx->pipelineCache().stats().created, before) << "a mip pipeline was made for baked textures";
  EXPECT_EQ(b.stats().mipGpuMs, 0.0) << "a mip pass ran";
  render::GpuScene deferred(*ctx, baked, render::MipMode::Compute, {}, render::GeometryUpload::Auto,
                            render::TextureLoad::Deferred);
  deferred.updateTextures(true);
  const render::GpuScene compute(*ctx, files, render::MipMode::Compute), host(*ctx, files, render::MipMode::Auto);
  render::HeadlessRenderer rb(*ctx, b, {kW, kH}), rd(*ctx, deferred, {kW, kH}), rc(*ctx, compute, {kW, kH}),
      rh(*ctx, host, {kW, kH});
  for (int mode : {VIEW_ALBEDO, VIEW_SHADED, VIEW_MIP_LEVEL}) {
    const ImageRGBA8 x = rb.render(pose, lens, settings(mode)).image;
    EXPECT_EQ(rd.render(pose, lens, settings(mode)).image.pixels, x.pixels) << "deferred and waited loads differ, mode " << mode;
    for (render::HeadlessRenderer* other : {&rc, &rh}) {
      const ImageRGBA8 y = other->render(pose, lens, settings(mode)).image;
      int worst = 0;
      size_t differ = 0;
      for (size_t i = 0; i < x.pixels.size(); ++i) {
        worst = std::max(worst, std::abs(int(x.pixels[i]) - int(y.pixels[i])));
        differ += x.pixels[i] != y.pixels[i];
      }
      std::printf("baked vs %s mips, view %d: %zu of %zu bytes differ, by at most %d\n", other == &rc ? "compute" : "auto", mode,
                  differ, x.pixels.size(), worst);
      if (mode == VIEW_MIP_LEVEL) EXPECT_EQ(differ, 0u) << "the same levels are sampled";
      EXPECT_LE(worst, 3) << "mode " << mode;
      EXPECT_LT(differ, x.pixels.size() / 10) << "mode " << mode;
    }
  }
}

}  // namespace
}  // namespace rtr

namespace rtr {
namespace {

// --textures bc: BC1/BC3/BC4 images sampled by the GPU from the chains as baked (no mip pass); frames stay
// near the lossless ones (mean error of the texels a few LSB: rtr-bake prints it per level) and sample the
// same levels.
TEST_F(VulkanTest, BlockCompressedTexturesDrawNearTheLosslessOnes) {
  const Scene files = loadScene(test::assetDir() / "temple.rtrscene");
  TexturePlan plan = planTextures(files, "t", false), bcPlan = plan;
  bakeTexels(plan, 0, "MTL");
  std::vector<LevelError> error;
  bakeTexels(bcPlan, 0, "MTL", {}, true, &error);
  size_t bc = 0;
  for (const Texture& t : bcPlan.scene.textures) bc += bakedBlocks(t.baked->format);
  EXPECT_EQ(bc, bcPlan.scene.textures.size());
  ASSERT_FALSE(error.empty());
  EXPECT_GT(error[0].sumAbs, 0.0) << "BC is lossy";
  const CameraPose pose = *files.defaultView;
  const Lens lens = fitDepthRange(Lens{}, files.bounds(), pose);
  const render::GpuScene lossless(*ctx, plan.scene, render::MipMode::Compute),
      blocks(*ctx, bcPlan.scene, render::MipMode::Compute);
  EXPECT_EQ(blocks.stats().mipGpuMs, 0.0) << "a mip pass ran";
  render::HeadlessRenderer a(*ctx, lossless, {kW, kH}), b(*ctx, blocks, {kW, kH});
  for (int mode : {VIEW_ALBEDO, VIEW_SHADED, VIEW_MIP_LEVEL}) {
    const ImageRGBA8 x = a.render(pose, lens, settings(mode)).image, y = b.render(pose, lens, settings(mode)).image;
    double sum = 0;
    size_t differ = 0;
    for (size_t i = 0; i < x.pixels.size(); ++i) {
      sum += std::abs(int(x.pixels[i]) - int(y.pixels[i]));
      differ += x.pixels[i] != y.pixels[i];
    }
    std::printf("bc vs lossless, view %d: %zu of %zu bytes differ, mean %.3f LSB\n", mode, differ, x.pixels.size(),
                sum / double(x.pixels.size()));
    // The same levels are sampled, but where BC3's alpha moves an alpha-tested edge (a few pixels).
    if (mode == VIEW_MIP_LEVEL) EXPECT_LT(differ, x.pixels.size() / 1000);
    else EXPECT_GT(differ, 0u) << "mode " << mode << ": BC textures were not used";
    EXPECT_LT(sum / double(x.pixels.size()), 2.0) << "mode " << mode;
  }
}

}  // namespace
}  // namespace rtr
