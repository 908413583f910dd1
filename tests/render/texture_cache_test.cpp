// The texture cache on the GPU (scene/texture_cache.hpp, GpuScene): the first open stores each texture's
// chain as the GPU made it, the second takes every texture from the cache (counted: no decode, no mip pass),
// and both draw exactly what an open without the cache draws, byte for byte, for every mip mode and for a
// deferred load. The rule that makes this hold: an entry's key names the device, the driver and the mip mode
// (and its version), and its texels are the GPU's own chain, read back.
#include <filesystem>

#include <unistd.h>

#include <gtest/gtest.h>

#include "core/image.hpp"
#include "render/headless.hpp"
#include "scene/load.hpp"
#include "scene/texture_cache.hpp"
#include "test_paths.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using test::VulkanTest;
namespace fs = std::filesystem;
constexpr uint32_t kW = 320, kH = 180;

render::RenderSettings settings(int mode) {
  render::RenderSettings s;
  s.mode = mode;
  s.shading = render::ShadingPath::Forward;
  s.mosaic = render::MosaicMode::Off;
  return s;
}

size_t entries(const fs::path& dir) {
  size_t n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) n += e.path().extension() == ".rtrtex";
  return n;
}

TEST_F(VulkanTest, ACachedOpenDrawsExactlyWhatAnUncachedOpenDraws) {
  const fs::path dir = fs::temp_directory_path() / ("rtr-texcache-gpu-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  const CameraPose pose = *scene.defaultView;
  const Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
  // One folder for every mode: a mode never takes another's chains (they differ in their last bits).
  TextureCache cache(dir, uint64_t(1) << 30);
  size_t stored = 0;
  for (render::MipMode mode : {render::MipMode::Compute, render::MipMode::Blit, render::MipMode::Auto}) {
    SCOPED_TRACE(enumName(mode));
    const render::GpuScene plain(*ctx, scene, mode);
    const uint32_t textures = plain.textureCount();
    ASSERT_GT(textures, 5u);
    std::vector<ImageRGBA8> want;
    render::HeadlessRenderer rp(*ctx, plain, {kW, kH});
    for (int view : {VIEW_SHADED, VIEW_ALBEDO, VIEW_MIP_LEVEL}) want.push_back(rp.render(pose, lens, settings(view)).image);
    auto same = [&](const render::GpuScene& g, const char* which) {
      render::HeadlessRenderer r(*ctx, g, {kW, kH});
      size_t k = 0;
      for (int view : {VIEW_SHADED, VIEW_ALBEDO, VIEW_MIP_LEVEL})
        EXPECT_EQ(r.render(pose, lens, settings(view)).image.pixels, want[k++].pixels) << which << ", view " << view;
    };
    {
      const render::GpuScene first(*ctx, scene, mode, {}, render::GeometryUpload::Auto, render::TextureLoad::Wait, &cache);
      EXPECT_EQ(first.stats().cacheHits, 0u);
      EXPECT_EQ(first.stats().cacheMisses, textures);
      EXPECT_EQ(first.stats().imagesDecoded, textures);
      same(first, "the open that filled the cache");
    }  // its entries are written by now
    EXPECT_EQ(entries(cache.dir()), stored += textures);
    const render::GpuScene second(*ctx, scene, mode, {}, render::GeometryUpload::Auto, render::TextureLoad::Wait, &cache);
    EXPECT_EQ(second.stats().cacheHits, textures);
    EXPECT_EQ(second.stats().cacheMisses, 0u);
    EXPECT_EQ(second.stats().imagesDecoded, 0u) << "a cache hit decoded its image";
    EXPECT_EQ(second.stats().mipGpuMs, 0.0) << "a mip pass ran for cached chains";
    same(second, "the open from the cache");
    render::GpuScene deferred(*ctx, scene, mode, {}, render::GeometryUpload::Auto, render::TextureLoad::Deferred, &cache);
    deferred.updateTextures(true);
    EXPECT_EQ(deferred.stats().cacheHits, textures);
    same(deferred, "a deferred open from the cache");
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rtr
