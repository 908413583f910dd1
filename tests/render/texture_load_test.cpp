// A deferred texture load: frames before the textures are in show the materials' factors; once
// updateTextures() takes them in, frames are bit-identical to those of a load that waited for them.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "core/image.hpp"
#include "render/headless.hpp"
#include "scene/load.hpp"
#include "scene/textures.hpp"
#include "vk/pipeline_cache.hpp"
#include "test_paths.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using test::VulkanTest;
constexpr uint32_t kW = 320, kH = 180;

render::RenderSettings settings(int mode, render::ShadingPath path, render::RasterPath raster = render::RasterPath::Auto) {
  render::RenderSettings s;
  s.mode = mode;
  s.shading = path;
  s.raster = raster;
  s.mosaic = render::MosaicMode::Off;
  return s;
}

TEST_F(VulkanTest, DeferredTexturesShowFactorsThenMatchAWaitedLoad) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  const CameraPose pose = *scene.defaultView;
  const Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
  // Both alive at once, so that neither reuses memory the other filled.
  const render::GpuScene waited(*ctx, scene, render::MipMode::Compute);
  render::GpuScene deferred(*ctx, scene, render::MipMode::Compute, {}, render::GeometryUpload::Auto,
                            render::TextureLoad::Deferred);
  ASSERT_TRUE(waited.texturesReady());
  ASSERT_FALSE(deferred.texturesReady());
  EXPECT_EQ(deferred.textureCount(), waited.textureCount());
  render::HeadlessRenderer a(*ctx, waited, {kW, kH}), b(*ctx, deferred, {kW, kH});

  // Before: every pixel of a material with a base-colour texture shows its factor in the albedo view
  // (pixels found by their visibility ids; the forward albedo view covers the same pixels but at a few edges).
  const auto ids = b.ids(pose, lens, settings(VIEW_SHADED, render::ShadingPath::Visibility));
  const ImageRGBA8 before = b.render(pose, lens, settings(VIEW_ALBEDO, render::ShadingPath::Forward)).image;
  const ImageRGBA8 textured = a.render(pose, lens, settings(VIEW_ALBEDO, render::ShadingPath::Forward)).image;
  std::vector<uint32_t> drawMaterial(64, UINT32_MAX);
  for (size_t k = 0; k < render::kDrawKindCount; ++k)
    for (const render::DrawItem& d : deferred.draws(render::DrawKind(k))) {
      if (d.id >= drawMaterial.size()) drawMaterial.resize(d.id + 1, UINT32_MAX);
      drawMaterial[d.id] = d.material;
    }
  size_t texturedPixels = 0, factorPixels = 0, differFromTextured = 0;
  for (uint32_t i = 0; i < kW * kH; ++i) {
    if (ids[i] == VIS_EMPTY) continue;
    const Material& m = scene.materials.at(drawMaterial.at(deferred.decodeVisId(ids[i]).first));
    if (m.texture(TextureSlot::BaseColor) == kNoTexture) continue;
    ++texturedPixels;
    bool factor = true, same = true;
    for (int c = 0; c < 3; ++c) {
      const int want = int(std::lround(linearToSrgb(m.baseColor[c]) * 255.0f));
      factor &= std::abs(int(before.pixels[i * 4 + c]) - want) <= 1;
      same &= before.pixels[i * 4 + c] == textured.pixels[i * 4 + c];
    }
    factorPixels += factor;
    differFromTextured += !same;
  }
  EXPECT_GT(texturedPixels, size_t(kW * kH / 4));
  EXPECT_GE(factorPixels, texturedPixels * 99 / 100) << "of " << texturedPixels << " textured pixels";
  EXPECT_GT(differFromTextured, texturedPixels / 2);

  // After: the same frames as the waited load, bit for bit, on every path (pipelines built before and after).
  // Taken in between frames, as the window does: frames go on while the upload and mips run.
  for (int frames = 0; !deferred.updateTextures(); ++frames) {
    ASSERT_LT(frames, 100000);
    b.render(pose, lens, settings(VIEW_SHADED, render::ShadingPath::Visibility));
  }
  EXPECT_TRUE(deferred.texturesReady());
  EXPECT_FALSE(deferred.updateTextures(true)) << "true once";
  for (auto path : {render::ShadingPath::Forward, render::ShadingPath::Visibility})
    for (auto raster : {render::RasterPath::Hardware, render::RasterPath::Compute})
      for (int mode : {VIEW_ALBEDO, VIEW_SHADED, VIEW_MIP_LEVEL}) {
        const auto s = settings(mode, path, raster);
        EXPECT_TRUE(a.render(pose, lens, s).image.pixels == b.render(pose, lens, s).image.pixels)
            << rtr::enumName(path) << " " << rtr::enumName(raster) << " mode " << mode;
      }
}

// Textures stream in one batch at a time: with a budget of one byte each batch is one texture, even with
// every texture decoded already. In every frame between, a pixel whose material's base-colour texture is
// in shows exactly the waited load's texel, any other its material's factor: never an unwritten descriptor
// or a texture still being written (validation with synchronization checks watches). At the end, frames
// equal the waited load's bit for bit.
TEST_F(VulkanTest, StreamedTexturesArriveOneByOneShowingFactorsUntilThen) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  const CameraPose pose = *scene.defaultView;
  const Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
  const render::GpuScene waited(*ctx, scene, render::MipMode::Compute);
  render::GpuScene streamed(*ctx, scene, render::MipMode::Compute, {}, render::GeometryUpload::Auto,
                            render::TextureLoad::Deferred);
  streamed.setUploadBudget(1);
  render::HeadlessRenderer a(*ctx, waited, {kW, kH}), b(*ctx, streamed, {kW, kH});
  const auto albedo = settings(VIEW_ALBEDO, render::ShadingPath::Forward);
  const ImageRGBA8 textured = a.render(pose, lens, albedo).image;
  const auto ids = b.ids(pose, lens, settings(VIEW_SHADED, render::ShadingPath::Visibility));
  std::vector<uint32_t> drawMaterial;
  for (size_t k = 0; k < render::kDrawKindCount; ++k)
    for (const render::DrawItem& d : streamed.draws(render::DrawKind(k))) {
      if (d.id >= drawMaterial.size()) drawMaterial.resize(d.id + 1, UINT32_MAX);
      drawMaterial[d.id] = d.material;
    }
  std::vector<uint32_t> gpuIndex(scene.textures.size(), UINT32_MAX);
  const std::vector<uint32_t> used = sampledTextures(scene);
  for (uint32_t i = 0; i < used.size(); ++i) gpuIndex[used[i]] = i;
  while (streamed.texturesDecoded() < streamed.textureCount()) std::this_thread::sleep_for(std::chrono::milliseconds(5));

  size_t mixedFrames = 0, before = 0;
  for (int calls = 0; !streamed.texturesReady(); ++calls) {
    ASSERT_LT(calls, 100000);
    streamed.updateTextures();
    const size_t in = streamed.texturesIn();
    ASSERT_LE(in, before + 1) << "more than one texture in one batch under a one-byte budget";
    if (in == before && !streamed.texturesReady()) continue;
    before = in;
    const ImageRGBA8 frame = b.render(pose, lens, albedo).image;
    size_t shownIn = 0, shownFactor = 0, wrong = 0;
    for (uint32_t i = 0; i < kW * kH; ++i) {
      if (ids[i] == VIS_EMPTY) continue;
      const Material& m = scene.materials.at(drawMaterial.at(streamed.decodeVisId(ids[i]).first));
      if (m.texture(TextureSlot::BaseColor) == kNoTexture) continue;
      if (streamed.textureIn(gpuIndex.at(m.texture(TextureSlot::BaseColor)))) {
        ++shownIn;
        wrong += !std::equal(&frame.pixels[i * 4], &frame.pixels[i * 4 + 3], &textured.pixels[i * 4]);
        continue;
      }
      ++shownFactor;
      for (int c = 0; c < 3; ++c)
        wrong += std::abs(int(frame.pixels[i * 4 + c]) - int(std::lround(linearToSrgb(m.baseColor[c]) * 255.0f))) > 1;
    }
    // Forward albedo pixels at a few silhouette edges may belong to another mesh than their id says.
    EXPECT_LE(wrong, (shownIn + shownFactor) / 100)
        << "after " << in << " textures: " << shownIn << " in, " << shownFactor << " showing the factor";
    mixedFrames += shownIn > 0 && shownFactor > 0;
  }
  EXPECT_EQ(streamed.texturesIn(), streamed.textureCount());
  EXPECT_GT(mixedFrames, 0u) << "no frame showed some textures in and some not";
  for (auto path : {render::ShadingPath::Forward, render::ShadingPath::Visibility})
    for (int mode : {VIEW_ALBEDO, VIEW_SHADED, VIEW_MIP_LEVEL}) {
      const auto s = settings(mode, path);
      EXPECT_TRUE(a.render(pose, lens, s).image.pixels == b.render(pose, lens, s).image.pixels)
          << rtr::enumName(path) << " mode " << mode;
    }
}

// --mips auto (the CPU device's default): the temple's small textures get chains made on the CPU as they
// decode, so no mip pipeline is made and no mip pass runs; its frames differ from the compute path's
// (within 1 LSB of the same reference per level) only slightly, and a deferred load matches a waited one.
TEST_F(VulkanTest, AutoMipsMakeSmallTexturesChainsOnTheCpu) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  const CameraPose pose = *scene.defaultView;
  const Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
  const uint32_t before = ctx->pipelineCache().stats().created;
  const render::GpuScene host(*ctx, scene, render::MipMode::Auto);
  EXPECT_EQ(ctx->pipelineCache().stats().created, before) << "a mip pipeline was made";
  EXPECT_EQ(host.stats().mipGpuMs, 0.0) << "a mip pass ran";
  const render::GpuScene compute(*ctx, scene, render::MipMode::Compute);
  render::GpuScene deferred(*ctx, scene, render::MipMode::Auto, {}, render::GeometryUpload::Auto, render::TextureLoad::Deferred);
  deferred.updateTextures(true);
  render::HeadlessRenderer a(*ctx, host, {kW, kH}), b(*ctx, compute, {kW, kH}), c(*ctx, deferred, {kW, kH});
  for (int mode : {VIEW_ALBEDO, VIEW_SHADED}) {
    const auto s = settings(mode, render::ShadingPath::Forward);
    const ImageRGBA8 x = a.render(pose, lens, s).image, y = b.render(pose, lens, s).image;
    EXPECT_EQ(c.render(pose, lens, s).image.pixels, x.pixels) << "deferred and waited Auto loads differ, mode " << mode;
    int worst = 0;
    size_t differ = 0;
    for (size_t i = 0; i < x.pixels.size(); ++i) {
      worst = std::max(worst, std::abs(int(x.pixels[i]) - int(y.pixels[i])));
      differ += x.pixels[i] != y.pixels[i];
    }
    std::printf("auto vs compute mips, view %d: %zu of %zu bytes differ, by at most %d\n", mode, differ, x.pixels.size(), worst);
    EXPECT_LE(worst, 3) << "mode " << mode;  // 1 LSB per level, blended by trilinear filtering and shading
    EXPECT_LT(differ, x.pixels.size() / 10) << "mode " << mode;
  }
}

// A waited load in batches: every batch goes through the one staging ring (no staging buffer per texture,
// the ring two batches long however many textures pass), and the frames are those of a load in one batch.
TEST_F(VulkanTest, TexturesGoThroughOneStagingRingBatchByBatch) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  const CameraPose pose = *scene.defaultView;
  const Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
  constexpr size_t kBudget = 64 << 10;  // the temple's largest level 0 (160 x 100 RGBA8) fits
  const render::GpuScene whole(*ctx, scene, render::MipMode::Compute, {}, render::GeometryUpload::Auto, render::TextureLoad::Wait,
                               nullptr, size_t(1) << 30);
  const render::GpuScene batched(*ctx, scene, render::MipMode::Compute, {}, render::GeometryUpload::Auto,
                                 render::TextureLoad::Wait, nullptr, kBudget);
  render::GpuScene streamed(*ctx, scene, render::MipMode::Compute, {}, render::GeometryUpload::Auto,
                            render::TextureLoad::Deferred, nullptr, kBudget);
  streamed.updateTextures(true);
  EXPECT_EQ(whole.stats().uploadBatches, 1u);
  for (const render::GpuScene* s : {&batched, static_cast<const render::GpuScene*>(&streamed)}) {
    EXPECT_GT(s->stats().uploadBatches, 2u);
    EXPECT_LT(s->stats().uploadBatches, s->textureCount()) << "batches of one texture: the budget is not used";
    EXPECT_EQ(s->stats().stagingAllocations, 1u) << "staging memory allocated per batch or per texture";
    EXPECT_EQ(s->stats().stagingBytes, 2 * kBudget);
  }
  render::HeadlessRenderer a(*ctx, whole, {kW, kH}), b(*ctx, batched, {kW, kH}), c(*ctx, streamed, {kW, kH});
  for (int mode : {VIEW_ALBEDO, VIEW_SHADED, VIEW_MIP_LEVEL})
    for (render::ShadingPath path : {render::ShadingPath::Forward, render::ShadingPath::Visibility}) {
      const ImageRGBA8 want = a.render(pose, lens, settings(mode, path)).image;
      EXPECT_EQ(b.render(pose, lens, settings(mode, path)).image.pixels, want.pixels) << "mode " << mode;
      EXPECT_EQ(c.render(pose, lens, settings(mode, path)).image.pixels, want.pixels) << "mode " << mode;
    }
}

}  // namespace
}  // namespace rtr
