// Level of detail in the culling pass (docs/virtual-geometry.md): threshold 0 is exactly the image without
// a hierarchy; a closed mesh seen from inside at 4 pixels of error shows no background through a crack;
// culling with a cut equals no culling with it; the image error against full detail stays small.
#include <cmath>
#include <cstring>
#include <set>
#include <cstdio>

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "cluster_lod.h"
#include "core/bounds.hpp"
#include "core/camera.hpp"
#include "render/cull.hpp"
#include "render/headless.hpp"
#include "vk/commands.hpp"
#include "scene/cluster_lod.hpp"
#include "scene/clusters.hpp"
#include "scene/load.hpp"
#include "test_paths.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

class LodTest : public test::VulkanTest {};

render::RenderSettings settings(float lodError, render::Culling cull = render::Culling::Off) {
  render::RenderSettings s;
  s.raster = render::RasterPath::Compute;
  s.mosaic = render::MosaicMode::Off;
  s.lodError = lodError;
  s.cull = cull;
  return s;
}

Scene withoutHierarchy(Scene s) {
  for (Mesh& m : s.meshes) m.lod = {};
  return s;
}

size_t hierarchies(const Scene& s) {
  size_t n = 0;
  for (const Mesh& m : s.meshes) n += m.lod.levels > 1;
  return n;
}

std::vector<CameraPose> templeViews(const Scene& scene, float aspect) {
  const Bounds b = scene.bounds();
  const CameraPose inside = scene.defaultView.value_or(CameraPose{b.center(), 0, 0});
  return {orbitFrame(b, Lens{}, aspect, 30.0f, -25.0f),
          inside,
          {inside.position, inside.yawDeg + 120.0f, inside.pitchDeg - 10.0f},
          orbitFrame(b, Lens{}, aspect, 200.0f, -5.0f)};
}

TEST_F(LodTest, ThresholdZeroIsExactlyTheImageWithoutAHierarchy) {
  if (!render::ComputeRaster::supported(*ctx)) GTEST_SKIP() << "no 64-bit buffer atomics";
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  ASSERT_GT(hierarchies(scene), 0u) << "rtr-bake stores the hierarchy";
  const Scene plain = withoutHierarchy(scene);
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute), gpuPlain(*ctx, plain, render::MipMode::Compute);
  EXPECT_GT(gpu.clusterCount(), gpu.baseClusterCount());
  EXPECT_EQ(gpuPlain.clusterCount(), gpu.baseClusterCount());
  const VkExtent2D e{320, 200};
  render::HeadlessRenderer a(*ctx, gpu, e), b(*ctx, gpuPlain, e);
  for (const CameraPose& pose : templeViews(scene, 1.6f))
    for (render::Culling cull : {render::Culling::Off, render::Culling::TwoPhase}) {
      const Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
      // The same (instance, triangle) at every pixel; the ids themselves differ (the hierarchy's triangles
      // lengthen each instance's id range, frame.h).
      const std::vector<uint32_t> withIds = a.ids(pose, lens, settings(0.0f, cull)),
                                  plainIds = b.ids(pose, lens, settings(0.0f, cull));
      ASSERT_EQ(withIds.size(), plainIds.size());
      size_t differ = 0;
      for (size_t i = 0; i < withIds.size(); ++i)
        differ += withIds[i] == VIS_EMPTY || plainIds[i] == VIS_EMPTY
                      ? withIds[i] != plainIds[i]
                      : gpu.decodeVisId(withIds[i]) != gpuPlain.decodeVisId(plainIds[i]);
      EXPECT_EQ(differ, 0u);
      EXPECT_EQ(a.render(pose, lens, settings(0.0f, cull)).image.pixels, b.render(pose, lens, settings(0.0f, cull)).image.pixels);
    }
}

TEST_F(LodTest, CulledFramesEqualUnculledOnesWithACut) {
  if (!render::ComputeRaster::supported(*ctx)) GTEST_SKIP() << "no 64-bit buffer atomics";
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  const VkExtent2D e{320, 200};
  render::HeadlessRenderer culled(*ctx, gpu, e), frustum(*ctx, gpu, e), unculled(*ctx, gpu, e), automatic(*ctx, gpu, e);
  uint32_t byLod = 0, byFrustum = 0, byCone = 0;
  for (const CameraPose& pose : templeViews(scene, 1.6f)) {
    const Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
    const std::vector<uint32_t> want = unculled.ids(pose, lens, settings(2.0f)),
                                got = culled.ids(pose, lens, settings(2.0f, render::Culling::TwoPhase)),
                                single = frustum.ids(pose, lens, settings(2.0f, render::Culling::Frustum));
    size_t differ = 0, differSingle = 0;
    for (size_t i = 0; i < want.size(); ++i) differ += want[i] != got[i], differSingle += want[i] != single[i];
    EXPECT_EQ(differ, 0u);
    EXPECT_EQ(differSingle, 0u) << "frustum and cones in the cut's pass";
    const auto c = unculled.renderer().cullStats(0);
    ASSERT_TRUE(c);
    byLod += c->lod;
    EXPECT_EQ(c->frustum + c->cone + c->occlusion, 0u) << "without --cull only the cut is chosen";
    const auto f = frustum.renderer().cullStats(0);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->occlusion, 0u) << "one pass, no pyramid";
    EXPECT_EQ(f->early, 0u);
    byFrustum += f->frustum, byCone += f->cone;
    // The default, auto: with a cut, the one pass of frustum and cones; at full detail, no pass.
    EXPECT_EQ(automatic.ids(pose, lens, settings(2.0f, render::Culling::Auto)), want);
    const auto a = automatic.renderer().cullStats(0);
    ASSERT_TRUE(a);
    EXPECT_EQ(a->frustum, f->frustum);
    EXPECT_EQ(a->cone, f->cone);
    EXPECT_EQ(a->occlusion + a->early, 0u);
    automatic.ids(pose, lens, settings(0.0f, render::Culling::Auto));
    EXPECT_FALSE(automatic.renderer().cullStats(0)) << "auto culls nothing without a cut";
  }
  EXPECT_GT(byLod, 0u);
  EXPECT_GT(byFrustum, 0u) << "--cull frustum tested no frustum";
  EXPECT_GT(byCone, 0u) << "--cull frustum tested no cone";
}

// The level window (cull_instances.comp): the temple placed 36 times in a 6 x 6 grid, seen from beside it
// at 2 px. Far instances skip their full-detail clusters (fewer clusters are visited than the instances
// hold), and the cut is the one each cluster's own test picks: the triangles listed equal the CPU's sum
// over every (instance, cluster) of cluster_lod.h's lodSelected (up to rounding at the threshold).
TEST_F(LodTest, LevelWindowVisitsFewerClustersAndKeepsTheCut) {
  if (!render::ComputeRaster::supported(*ctx)) GTEST_SKIP() << "no 64-bit buffer atomics";
  Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  const Bounds one = scene.bounds();
  const glm::vec3 step = (one.max - one.min) * 1.5f;
  scene.instances.clear();
  for (int i = 0; i < 36; ++i)
    for (uint32_t m = 0; m < scene.meshes.size(); ++m)
      scene.instances.push_back(
          {m, glm::translate(glm::mat4(1.0f), glm::vec3(step.x * float(i % 6), 0.0f, -step.z * float(i / 6)))});
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  const VkExtent2D e{320, 200};
  render::HeadlessRenderer r(*ctx, gpu, e);
  const Bounds b = scene.bounds();
  for (const CameraPose& pose : {orbitFrame(b, Lens{}, 1.6f, 200.0f, -10.0f), CameraPose{one.center(), 200.0f, -5.0f}}) {
    const Lens lens = fitDepthRange(Lens{}, b, pose);
    r.ids(pose, lens, settings(2.0f));
    const auto c = r.renderer().cullStats(0);
    ASSERT_TRUE(c);
    const float ppu = float(e.height) / (2.0f * std::tan(glm::radians(lens.fovYDeg) * 0.5f));
    uint64_t want = 0;
    for (const Instance& in : scene.instances) {
      const Mesh& m = scene.meshes[in.mesh];
      if (m.indices.empty() || scene.materials[m.material].blended()) continue;
      if (m.lod.levels == 0) want += m.indices.size() / 3;  // no hierarchy: always in the cut
      const glm::vec4 t(glm::vec3(in.transform[3]), 0.0f);
      for (const LodCluster& k : m.lod.clusters)
        if (shader::lodSelected(k.sphere + t, k.error, k.parentSphere + t, k.parentError, pose.position, ppu, lens.zNear, 2.0f))
          want += k.triangleCount;
    }
    std::printf("%u of %u clusters visited, %u instances skipped whole; %u triangles listed, CPU %llu\n", c->tested,
                gpu.clusterCount(), c->instancesCulled, c->triangles, (unsigned long long)want);
    EXPECT_LT(c->tested, gpu.clusterCount() / 2) << "the window skips little";
    EXPECT_NEAR(double(c->triangles), double(want), double(want) / 1000);
  }
}

// The trees over each level (cull_instances.comp) prune only what the clusters' own tests would drop:
// 36 temples, some turned, scaled and mirrored, seen from beside the grid and from inside one at 1 and
// 4 px, frustum and cone on; the culling pass lists the same (instance, cluster) pairs with the trees
// pruning as with every node descended (each cluster of every level tested), with far fewer tests.
TEST_F(LodTest, TreesListTheClustersTheFlatTestLists) {
  Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  const Bounds one = scene.bounds();
  const glm::vec3 step = (one.max - one.min) * 1.5f;
  scene.instances.clear();
  for (int i = 0; i < 36; ++i) {
    glm::mat4 t = glm::translate(glm::mat4(1.0f), glm::vec3(step.x * float(i % 6), 0.0f, -step.z * float(i / 6)));
    if (i % 3 == 1) t = glm::rotate(t, glm::radians(40.0f * float(i)), glm::vec3(0, 1, 0));
    if (i % 5 == 2) t = glm::scale(t, glm::vec3(0.6f));
    if (i % 7 == 3) t = glm::scale(t, glm::vec3(-1.0f, 1.0f, 1.0f));
    if (i % 11 == 4) t = glm::scale(t, glm::vec3(1.0f, 1.5f, 1.0f));  // non-uniform: no cone
    for (uint32_t m = 0; m < scene.meshes.size(); ++m) scene.instances.push_back({m, t});
  }
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  ASSERT_GT(gpu.cullQueueCapacity().size(), 1u) << "the temple's trees have inner nodes";
  render::ClusterCuller culler(*ctx, gpu.clusterCount(), gpu.chunkCapacity(), gpu.cullQueueCapacity());
  const VkExtent2D e{320, 200};
  const Bounds b = scene.bounds();
  uint64_t sumFlat = 0, sumTree = 0;
  for (const CameraPose& pose : {orbitFrame(b, Lens{}, 1.6f, 200.0f, -10.0f), CameraPose{one.center(), 200.0f, -5.0f}})
    for (float threshold : {1.0f, 4.0f}) {
      const Lens lens = fitDepthRange(Lens{}, b, pose);
      const float ppu = float(e.height) / (2.0f * std::tan(glm::radians(lens.fovYDeg) * 0.5f));
      const render::CullCamera cam{projectionMatrix(lens, float(e.width) / float(e.height)) * viewMatrix(pose),
                                   pose.position,
                                   false,
                                   threshold,
                                   ppu,
                                   lens.zNear};
      auto run = [&](bool nodes) {
        render::CullTests tests;
        tests.nodes = nodes;
        const size_t n = gpu.clusterCount();
        vk::Buffer back(*ctx, sizeof(shader::CullCounts) + n * 8, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback,
                        "cull back");
        vk::submitAndWait(*ctx, [&](VkCommandBuffer cb) {
          culler.record(cb, gpu.clusters(), gpu.clusterCount(), cam, nullptr, tests, render::CullPhase::Single, gpu.clusterLods(),
                        gpu.cullInstances(), gpu.cullInstanceCount(), gpu.cullNodes(), gpu.instances());
          const VkBufferCopy a{0, 0, sizeof(shader::CullCounts)}, v{0, sizeof(shader::CullCounts), n * 8};
          vkCmdCopyBuffer(cb, culler.counts(), back.handle(), 1, &a);
          vkCmdCopyBuffer(cb, culler.visible(), back.handle(), 1, &v);
          vk::bufferBarrier(cb, vk::kCopyWrite, vk::kHostRead);
        });
        back.invalidate();
        std::pair<shader::CullCounts, std::set<std::pair<uint32_t, uint32_t>>> r;
        std::memcpy(&r.first, back.mapped(), sizeof(shader::CullCounts));
        const uint32_t* list = reinterpret_cast<const uint32_t*>(static_cast<const uint8_t*>(back.mapped()) + sizeof r.first);
        for (uint32_t i = 0; i < r.first.listed; ++i) EXPECT_TRUE(r.second.insert({list[2 * i], list[2 * i + 1]}).second);
        return r;
      };
      const auto flat = run(false), tree = run(true);
      std::printf("%.0f px: %u pairs listed, %u triangles; cluster tests %u flat, %u with the trees (+ %u node tests)\n",
                  threshold, tree.first.listed, tree.first.triangles, flat.first.tested, tree.first.tested, tree.first.nodes);
      EXPECT_GT(tree.first.listed, 0u);
      EXPECT_TRUE(flat.second == tree.second) << "flat " << flat.second.size() << " pairs, trees " << tree.second.size();
      EXPECT_EQ(flat.first.triangles, tree.first.triangles);
      if (flat.first.instancesCulled == 0) { EXPECT_EQ(flat.first.tested, gpu.clusterCount()) << "flat: every cluster tested"; }
      sumFlat += flat.first.tested, sumTree += tree.first.tested;
    }
  EXPECT_LT(sumTree * 2, sumFlat) << "the trees test under half of the clusters";
}

// The rendered error of a cut against full detail: the mean over pixels of the largest channel difference
// (0-255), and the share of pixels off by more than 64.
TEST_F(LodTest, ImageErrorAgainstFullDetailIsSmall) {
  if (!render::ComputeRaster::supported(*ctx)) GTEST_SKIP() << "no 64-bit buffer atomics";
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  const VkExtent2D e{640, 400};
  render::HeadlessRenderer r(*ctx, gpu, e);
  for (const CameraPose& pose : templeViews(scene, 1.6f)) {
    const Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
    const render::HeadlessFrame full = r.render(pose, lens, settings(0.0f));
    for (float threshold : {1.0f, 4.0f}) {
      const render::HeadlessFrame cut = r.render(pose, lens, settings(threshold));
      const auto c = r.renderer().cullStats(0);
      ASSERT_TRUE(c);
      double sum = 0;
      size_t large = 0, n = full.image.pixels.size() / 4;
      for (size_t i = 0; i < n; ++i) {
        int d = 0;
        for (int k = 0; k < 3; ++k)
          d = std::max(d, std::abs(int(full.image.pixels[4 * i + k]) - int(cut.image.pixels[4 * i + k])));
        sum += d, large += d > 64;
      }
      std::printf("lod %.0f px: %u triangles listed, mean error %.3f, %.3f %% of pixels off by > 64\n", threshold, c->triangles,
                  sum / double(n), 100.0 * double(large) / double(n));
      // Bounds from lavapipe's measurement (worst view: 0.094 and 0.018 % at 1 px, 0.28 and 0.077 % at 4 px)
      // with room for another device's rounding; projected errors 20 times too small fail the 1 px bounds.
      EXPECT_LT(sum / double(n), threshold <= 1.0f ? 0.15 : 0.5);
      EXPECT_LT(double(large) / double(n), threshold <= 1.0f ? 0.0005 : 0.002);
    }
  }
}

// A closed, bumpy sphere wound to face inwards (front faces seen from inside), poles welded.
Mesh insideOutSphere(uint32_t rings, uint32_t segments) {
  Mesh m;
  m.name = "room";
  m.positions.push_back({0, 1, 0});
  for (uint32_t i = 1; i < rings; ++i)
    for (uint32_t j = 0; j < segments; ++j) {
      const float th = float(i) / rings * 3.14159265f, ph = float(j) / segments * 6.2831853f;
      const float r = 1.0f + 0.05f * std::sin(7 * th) * std::cos(5 * ph);
      m.positions.push_back(r * glm::vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)));
    }
  m.positions.push_back({0, -1, 0});
  const uint32_t south = uint32_t(m.positions.size() - 1);
  auto at = [&](uint32_t i, uint32_t j) { return 1 + (i - 1) * segments + j % segments; };
  for (uint32_t j = 0; j < segments; ++j) {  // each triangle with two of its vertices swapped: inward
    m.indices.insert(m.indices.end(), {0, at(1, j), at(1, j + 1)});
    m.indices.insert(m.indices.end(), {south, at(rings - 1, j + 1), at(rings - 1, j)});
  }
  for (uint32_t i = 1; i + 1 < rings; ++i)
    for (uint32_t j = 0; j < segments; ++j) {
      m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j), at(i, j + 1)});
      m.indices.insert(m.indices.end(), {at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)});
    }
  for (const glm::vec3& p : m.positions) m.normals.push_back(-glm::normalize(p)), m.bounds.extend(p);
  return m;
}

TEST_F(LodTest, ClosedMeshFromInsideShowsNoCrack) {
  if (!render::ComputeRaster::supported(*ctx)) GTEST_SKIP() << "no 64-bit buffer atomics";
  Scene scene;
  scene.materials.push_back({});
  scene.meshes.push_back(insideOutSphere(200, 400));  // 159 200 triangles
  Mesh& m = scene.meshes[0];
  buildClusters(m, true);
  m.lod = buildClusterLod(m);
  ASSERT_GE(m.lod.levels, 5u);
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  const VkExtent2D e{320, 200};
  render::HeadlessRenderer r(*ctx, gpu, e);
  Lens lens;
  lens.zNear = 0.01f, lens.zFar = 10.0f;
  size_t holes = 0;
  for (const CameraPose& pose : {CameraPose{{0.5f, 0.2f, 0.1f}, -90.0f, 0.0f}, CameraPose{{0.5f, 0.2f, 0.1f}, 90.0f, 10.0f},
                                 CameraPose{{0, 0, 0}, 30.0f, -40.0f}, CameraPose{{-0.7f, -0.3f, 0.2f}, 45.0f, 60.0f}})
    for (render::Culling cull : {render::Culling::Off, render::Culling::Frustum, render::Culling::TwoPhase}) {
      const std::vector<uint32_t> ids = r.ids(pose, lens, settings(4.0f, cull));
      const auto c = r.renderer().cullStats(0);
      ASSERT_TRUE(c);
      size_t empty = 0;
      for (uint32_t id : ids) empty += id == VIS_EMPTY;
      std::printf("inside, yaw %.0f cull %s: %u of %u clusters listed, %u triangles; %zu px empty\n", pose.yawDeg, enumName(cull),
                  c->early + c->late, c->clusters, c->triangles, empty);
      EXPECT_EQ(empty, 0u) << "yaw " << pose.yawDeg << " cull " << enumName(cull);
      EXPECT_LT(c->triangles, m.triangleCount() / 2) << "coarser levels are drawn";
      holes += empty;
    }
  EXPECT_EQ(holes, 0u);
}

}  // namespace
}  // namespace rtr
