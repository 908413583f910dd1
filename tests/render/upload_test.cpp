// The scene upload's two ways into device memory give the same frames: written in place where the host
// maps device memory (every CPU device), or through a staging buffer and a copy (a GPU without a large
// BAR). The scene has 16- and 32-bit indices, textured and untextured meshes.
#include <gtest/gtest.h>

#include "render/headless.hpp"
#include "scene/load.hpp"
#include "test_paths.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using test::VulkanTest;

// The temple with a wavy untextured grid of 300 x 300 vertices (32-bit indices) across its middle.
Scene templeWithGrid() {
  Scene s = loadScene(test::assetDir() / "temple.rtrscene");
  const Bounds b = s.bounds();
  const glm::vec3 c = b.center(), e = b.extent();
  Mesh g;
  g.material = 0;
  constexpr uint32_t n = 300;
  for (uint32_t j = 0; j < n; ++j)
    for (uint32_t i = 0; i < n; ++i) {
      const float u = float(i) / (n - 1) - 0.5f, v = float(j) / (n - 1) - 0.5f;
      g.positions.push_back(c + glm::vec3(u * e.x * 0.6f, 0.05f * e.y * std::sin(20.0f * u), v * e.z * 0.6f));
      g.normals.push_back(glm::normalize(glm::vec3(-std::cos(20.0f * u), 1.0f, 0.0f)));
      g.bounds.extend(g.positions.back());
    }
  for (uint32_t j = 0; j + 1 < n; ++j)
    for (uint32_t i = 0; i + 1 < n; ++i) {
      const uint32_t a = j * n + i;
      g.indices.insert(g.indices.end(), {a, a + n, a + 1, a + 1, a + n, a + n + 1});
    }
  s.meshes.push_back(std::move(g));
  return s;
}

TEST_F(VulkanTest, StagedAndInPlaceGeometryUploadsRenderTheSame) {
  const Scene scene = templeWithGrid();
  const CameraPose pose = scene.defaultView.value_or(frameBounds(scene.bounds(), Lens{}, 16.0f / 9.0f));
  const Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
  // Both alive at once, so that neither reuses memory the other filled.
  const render::GpuScene inPlace(*ctx, scene, render::MipMode::Compute, {}, render::GeometryUpload::Auto);
  const render::GpuScene staged(*ctx, scene, render::MipMode::Compute, {}, render::GeometryUpload::Staging);
  std::vector<std::vector<uint8_t>> images[2];
  for (const render::GpuScene* gpu : {&inPlace, &staged}) {
    EXPECT_LT(gpu->stats().meshes16, gpu->stats().meshes) << "no mesh with 32-bit indices";
    render::HeadlessRenderer r(*ctx, *gpu, {320, 180});
    for (auto path : {render::ShadingPath::Visibility, render::ShadingPath::Forward})
      for (int mode : {VIEW_SHADED, VIEW_NORMAL}) {
        render::RenderSettings s;
        s.shading = path;
        s.mode = mode;
        images[gpu == &staged].push_back(r.render(pose, lens, s).image.pixels);
      }
  }
  ASSERT_EQ(images[0].size(), images[1].size());
  for (size_t i = 0; i < images[0].size(); ++i) EXPECT_TRUE(images[0][i] == images[1][i]) << "frame " << i << " differs";
}

}  // namespace
}  // namespace rtr
