// The scene upload's two ways into device memory give the same bytes and frames: written in place where
// the host maps device memory (direct), or through a ring of staging slots copied by the GPU (staged).
// The scene has 16- and 32-bit indices, textured and untextured meshes, and a hierarchy.
#include <cstdlib>

#include <gtest/gtest.h>

#include "render/headless.hpp"
#include "scene/load.hpp"
#include "test_paths.hpp"
#include "vk/commands.hpp"
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

std::vector<uint8_t> readBack(const vk::Context& ctx, const vk::Buffer& b) {
  vk::Buffer host(ctx, b.size(), VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback, "read-back");
  vk::submitAndWait(ctx, [&](VkCommandBuffer cb) {
    const VkBufferCopy region{0, 0, b.size()};
    vkCmdCopyBuffer(cb, b.handle(), host.handle(), 1, &region);
    vk::bufferBarrier(cb, vk::kCopyWrite, vk::kHostRead);
  });
  host.invalidate();
  const auto* p = static_cast<const uint8_t*>(host.mapped());
  return {p, p + b.size()};
}

// Every geometry buffer read back equals the direct upload's byte for byte, whether the staged ring's
// slots are the default's (a batch for each of the two passes here) or 64 KiB (more batches than slots,
// each slot written again after its copies; pieces larger than a slot grow it). indices16's last two
// bytes may be padding that nobody writes.
TEST_F(VulkanTest, DirectAndStagedGeometryUploadsWriteTheSameBytes) {
  const Scene scene = templeWithGrid();
  size_t indices16 = 0;
  for (const Mesh& m : scene.meshes)
    if (m.positions.size() <= 65536) indices16 += m.indices.size() + m.lod.indices.size();
  using render::GeometryUpload;
  const render::GpuScene direct(*ctx, scene, render::MipMode::Compute, {}, GeometryUpload::Direct);
  EXPECT_EQ(direct.stats().geometryUpload, GeometryUpload::Direct);
  EXPECT_EQ(direct.stats().geometryCopies, 0u);
  EXPECT_NE(direct.clusterLods(), VK_NULL_HANDLE) << "no hierarchy";
  EXPECT_LT(direct.stats().meshes16, direct.stats().meshes) << "no mesh with 32-bit indices";
  EXPECT_GT(direct.stats().meshes16, 0u) << "no mesh with 16-bit indices";
  for (size_t slot : {render::GpuScene::kGeometrySlotBytes, size_t(64) << 10}) {
    const render::GpuScene staged(*ctx, scene, render::MipMode::Compute, {}, GeometryUpload::Staged, render::TextureLoad::Wait,
                                  nullptr, render::GpuScene::kDefaultUploadBudget, slot);
    EXPECT_EQ(staged.stats().geometryUpload, GeometryUpload::Staged);
    // Small slots: more batches than slots, so slots are written again.
    EXPECT_GT(staged.stats().geometryCopies, slot < staged.stats().geometryBytes ? render::GpuScene::kGeometrySlots : 1u)
        << "slot " << slot;
    const auto a = direct.geometryBuffers(), b = staged.geometryBuffers();
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
      SCOPED_TRACE(std::string(a[i].first) + ", slot " + std::to_string(slot));
      ASSERT_EQ(a[i].second->handle() == VK_NULL_HANDLE, b[i].second->handle() == VK_NULL_HANDLE);
      if (!a[i].second->handle()) continue;
      ASSERT_EQ(a[i].second->size(), b[i].second->size());
      std::vector<uint8_t> x = readBack(*ctx, *a[i].second), y = readBack(*ctx, *b[i].second);
      if (std::string(a[i].first) == "indices16") x.resize(indices16 * 2), y.resize(indices16 * 2);
      size_t first = 0;
      while (first < x.size() && x[first] == y[first]) ++first;
      EXPECT_EQ(first, x.size()) << "first differing byte";
    }
  }
}

// The caller's default (Auto) is the direct path on every device: staging measured slower on the GPU
// hosts (docs/startup.md, "What the bus allows") and is one more copy on a CPU device. RTR_UPLOAD, the
// switch that chose staging for measuring, is gone: set, it changes nothing.
TEST_F(VulkanTest, TheGeometryGoesDirectByDefault) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  ::setenv("RTR_UPLOAD", "staged", 1);
  const render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  ::unsetenv("RTR_UPLOAD");
  EXPECT_EQ(gpu.stats().geometryUpload, render::GeometryUpload::Direct);
  EXPECT_EQ(gpu.stats().geometryCopies, 0u);
}

TEST_F(VulkanTest, StagedAndInPlaceGeometryUploadsRenderTheSame) {
  const Scene scene = templeWithGrid();
  const CameraPose pose = scene.defaultView.value_or(frameBounds(scene.bounds(), Lens{}, 16.0f / 9.0f));
  const Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
  // Both alive at once, so that neither reuses memory the other filled.
  const render::GpuScene inPlace(*ctx, scene, render::MipMode::Compute, {}, render::GeometryUpload::Direct);
  const render::GpuScene staged(*ctx, scene, render::MipMode::Compute, {}, render::GeometryUpload::Staged);
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
