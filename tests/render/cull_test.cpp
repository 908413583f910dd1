// Cluster culling (src/render/cull.hpp): the GPU pass agrees with the same tests run on the CPU, the depth
// pyramid is the exact farthest-depth reduction, and culling never removes a visible cluster: the temple's
// id image drawn from the kept clusters equals the one drawn from all of them, bit for bit.
#include <algorithm>
#include <cstring>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "core/camera.hpp"
#include "cull.h"
#include "render/cull.hpp"
#include "scene/load.hpp"
#include "scene/textures.hpp"
#include "test_paths.hpp"
#include "vk/commands.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using render::ClusterCuller;
using render::CullCamera;
using render::DepthPyramid;
using shader::GpuCluster;

// A host copy of the pyramid's levels (row-major floats per level).
struct HostPyramid {
  std::vector<VkExtent2D> sizes;
  std::vector<std::vector<float>> levels;
};

// The same reduction on the CPU, into the GPU's level sizes `sizes`.
HostPyramid cpuPyramid(const std::vector<float>& depth, VkExtent2D e, const std::vector<VkExtent2D>& sizes) {
  HostPyramid p;
  VkExtent2D s = e;
  for (const VkExtent2D d : sizes) {
    const std::vector<float>* src = p.levels.empty() ? &depth : &p.levels.back();
    std::vector<float> out(size_t(d.width) * d.height);
    for (uint32_t y = 0; y < d.height; ++y)
      for (uint32_t x = 0; x < d.width; ++x) {
        float m = 0.0f;
        for (uint32_t j = 0; j < 2; ++j)
          for (uint32_t i = 0; i < 2; ++i)
            m = std::max(m, (*src)[size_t(std::min(2 * y + j, s.height - 1)) * s.width + std::min(2 * x + i, s.width - 1)]);
        out[size_t(y) * d.width + x] = m;
      }
    p.sizes.push_back(d);
    p.levels.push_back(std::move(out));
    s = d;
  }
  return p;
}

// The pass's decision for one cluster, on the CPU, from the same formulas (cull.h).
uint32_t cpuCull(const GpuCluster& c, const CullCamera& cam, const HostPyramid* pyr, VkExtent2D e) {
  if (shader::frustumCulls(c.sphere, cam.viewProj)) return CULL_BY_FRUSTUM;
  if (shader::coneCulls(c.sphere, c.cone, cam.eye)) return CULL_BY_CONE;
  if (!pyr) return CULL_VISIBLE;
  const shader::ProjectedBox b = shader::projectBox(c.sphere, cam.viewProj, e.width, e.height);
  if (b.inFront == 0u) return CULL_VISIBLE;
  const int level = shader::pyramidLevel(b.pixels, int(pyr->levels.size()));
  const glm::ivec4 t = b.pixels >> (level + 1);
  float farthest = 0.0f;
  for (int y = t.y; y <= t.w; ++y)
    for (int x = t.x; x <= t.z; ++x) farthest = std::max(farthest, pyr->levels[level][size_t(y) * pyr->sizes[level].width + x]);
  return b.nearestDepth > farthest ? CULL_BY_OCCLUSION : CULL_VISIBLE;
}

struct GpuResult {
  std::set<uint32_t> visible;
  shader::CullCounts counts{};
};

class CullTest : public test::VulkanTest {
 protected:
  // Runs the pass (the pyramid already built, or none) and reads back its list and counts.
  GpuResult cull(ClusterCuller& culler, const vk::Buffer& clusters, uint32_t count, const CullCamera& cam,
                 const DepthPyramid* pyramid, const std::function<void(VkCommandBuffer)>& before = {}) {
    vk::Buffer back(*ctx, 32 + size_t(count) * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback, "cull back");
    vk::submitAndWait(*ctx, [&](VkCommandBuffer cb) {
      if (before) before(cb);
      culler.record(cb, clusters.handle(), count, cam, pyramid);
      VkBufferCopy a{0, 0, 32}, b{0, 32, size_t(count) * 4};
      vkCmdCopyBuffer(cb, culler.counts(), back.handle(), 1, &a);
      vkCmdCopyBuffer(cb, culler.visible(), back.handle(), 1, &b);
      vk::memoryBarrier(cb, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                        VK_ACCESS_2_HOST_READ_BIT);
    });
    back.invalidate();
    GpuResult r;
    std::memcpy(&r.counts, back.mapped(), 32);
    const uint32_t* ids = reinterpret_cast<const uint32_t*>(static_cast<const uint8_t*>(back.mapped()) + 32);
    EXPECT_LE(r.counts.dispatch[0], count);
    for (uint32_t i = 0; i < std::min(r.counts.dispatch[0], count); ++i) EXPECT_TRUE(r.visible.insert(ids[i]).second) << "listed twice";
    EXPECT_EQ(r.counts.dispatch[1], 1u);
    EXPECT_EQ(r.counts.dispatch[2], 1u);
    EXPECT_EQ(r.counts.dispatch[0] + r.counts.culled[0] + r.counts.culled[1] + r.counts.culled[2], count);
    return r;
  }

  HostPyramid readPyramid(const DepthPyramid& p) {
    HostPyramid h;
    std::vector<VkBufferImageCopy> regions;
    size_t total = 0;
    for (uint32_t l = 0; l < p.levels(); ++l) {
      const VkExtent2D e{std::max(1u, p.image().extent().width >> l), std::max(1u, p.image().extent().height >> l)};
      h.sizes.push_back(e);
      VkBufferImageCopy r{};
      r.bufferOffset = total * 4;
      r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, l, 0, 1};
      r.imageExtent = {e.width, e.height, 1};
      regions.push_back(r);
      total += size_t(e.width) * e.height;
    }
    vk::Buffer back(*ctx, total * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback, "pyramid back");
    vk::submitAndWait(*ctx, [&](VkCommandBuffer cb) {
      auto layout = [&](VkImageLayout from, VkImageLayout to) {
        vk::barrier(cb, {{p.image().handle(), from, to, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                          VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT, VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT}});
      };
      layout(VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
      vkCmdCopyImageToBuffer(cb, p.image().handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, back.handle(), uint32_t(regions.size()), regions.data());
      layout(VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL);
      vk::memoryBarrier(cb, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                        VK_ACCESS_2_HOST_READ_BIT);
    });
    back.invalidate();
    const float* f = static_cast<const float*>(back.mapped());
    for (size_t l = 0; l < regions.size(); ++l) {
      const size_t n = size_t(h.sizes[l].width) * h.sizes[l].height;
      h.levels.emplace_back(f + regions[l].bufferOffset / 4, f + regions[l].bufferOffset / 4 + n);
    }
    return h;
  }
};

CullCamera cameraFor(const CameraPose& pose, const Lens& lens, VkExtent2D e) {
  return {projectionMatrix(lens, float(e.width) / float(e.height)) * viewMatrix(pose), pose.position, lens.orthographic};
}

// Random clusters and cameras, and a random depth image of odd size: the GPU's pyramid is the CPU's
// reduction exactly, and its visible set and counts are the CPU's (up to clusters whose decision flips
// within float rounding of a test's threshold).
TEST_F(CullTest, GpuMatchesCpuForRandomClustersAndCameras) {
  const VkExtent2D e{203, 117};
  std::mt19937 rng(18);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> depth(size_t(e.width) * e.height);
  for (uint32_t y = 0; y < e.height; ++y)  // blocky depths: walls at various distances, some far background
    for (uint32_t x = 0; x < e.width; ++x) depth[size_t(y) * e.width + x] = ((x / 13 + y / 7) % 5 == 0) ? 1.0f : 0.9f + 0.1f * float((x * 7 + y * 3) % 11) / 11.0f;
  for (float& d : depth) d = std::min(d, 0.9f + 0.1f * u(rng));
  vk::Image depthImage(*ctx, {e, VK_FORMAT_R32_SFLOAT, 1, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, 0, 0, "depth"});
  vk::Buffer up(*ctx, depth.size() * 4, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUse::Upload, "depth up");
  std::memcpy(up.mapped(), depth.data(), depth.size() * 4);
  up.flush();

  constexpr uint32_t kCount = 5000;
  std::vector<GpuCluster> clusters(kCount);
  for (GpuCluster& c : clusters) {
    c.sphere = {u(rng) * 40 - 20, u(rng) * 40 - 20, u(rng) * 40 - 20, u(rng) * u(rng) * 3};
    c.cone = {glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f)), u(rng) * 2.4f - 1.2f};
    c.triangleCount = 1;
  }
  vk::Buffer buf(*ctx, kCount * sizeof(GpuCluster), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUse::Upload, "clusters");
  std::memcpy(buf.mapped(), clusters.data(), kCount * sizeof(GpuCluster));
  buf.flush();

  DepthPyramid pyramid(*ctx, e);
  ClusterCuller culler(*ctx, kCount);
  uint32_t byReason[4] = {}, borderline = 0;
  for (int view = 0; view < 6; ++view) {
    const CameraPose pose{{u(rng) * 30 - 15, u(rng) * 30 - 15, u(rng) * 30 - 15}, u(rng) * 360, u(rng) * 120 - 60};
    Lens lens;
    lens.zNear = 0.5f;
    lens.zFar = 40.0f + 30.0f * u(rng);
    const CullCamera cam = cameraFor(pose, lens, e);
    const bool occlusion = view % 2 == 0;
    const GpuResult got = cull(culler, buf, kCount, cam, occlusion ? &pyramid : nullptr, [&](VkCommandBuffer cb) {
      if (!occlusion) return;
      vk::barrier(cb, {{depthImage.handle(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                        VK_PIPELINE_STAGE_2_NONE, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE, VK_ACCESS_2_TRANSFER_WRITE_BIT}});
      VkBufferImageCopy r{};
      r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      r.imageExtent = {e.width, e.height, 1};
      vkCmdCopyBufferToImage(cb, up.handle(), depthImage.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &r);
      vk::barrier(cb, {{depthImage.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                        VK_PIPELINE_STAGE_2_COPY_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                        VK_ACCESS_2_SHADER_READ_BIT}});
      pyramid.build(cb, depthImage.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    });
    HostPyramid host;
    if (occlusion) {
      host = readPyramid(pyramid);
      const HostPyramid want = cpuPyramid(depth, e, host.sizes);
      ASSERT_EQ(host.levels.size(), want.levels.size());
      for (size_t l = 0; l < want.levels.size(); ++l) ASSERT_EQ(host.levels[l], want.levels[l]) << "pyramid level " << l;
    }
    uint32_t counts[4] = {};
    for (uint32_t i = 0; i < kCount; ++i) {
      const uint32_t r = cpuCull(clusters[i], cam, occlusion ? &host : nullptr, e);
      ++counts[r];
      ++byReason[r];
      if ((r == CULL_VISIBLE) == (got.visible.count(i) == 1)) continue;
      // A disagreement must sit on a threshold: a sphere 0.01 % larger or smaller decides both ways.
      GpuCluster grown = clusters[i], shrunk = clusters[i];
      grown.sphere.w = grown.sphere.w * 1.0001f + 1e-5f;
      shrunk.sphere.w = shrunk.sphere.w * 0.9999f;
      const bool edge = cpuCull(grown, cam, occlusion ? &host : nullptr, e) != cpuCull(shrunk, cam, occlusion ? &host : nullptr, e);
      EXPECT_TRUE(edge) << "view " << view << " cluster " << i << ": CPU says reason " << r;
      ++borderline;
    }
    if (borderline == 0)
      for (uint32_t k = 0; k < 3; ++k) EXPECT_EQ(got.counts.culled[k], counts[k + 1]) << "view " << view << " reason " << k + 1;
  }
  EXPECT_LE(borderline, 5u);
  // Every test must have culled something, or the comparison proves little.
  for (uint32_t r = 1; r < 4; ++r) EXPECT_GT(byReason[r], 50u) << "reason " << r;
  EXPECT_GT(byReason[CULL_VISIBLE], 50u);
  std::printf("random clusters over 6 views: visible %u, frustum %u, cone %u, occlusion %u, borderline %u\n",
              byReason[0], byReason[1], byReason[2], byReason[3], borderline);
}

}  // namespace
}  // namespace rtr
