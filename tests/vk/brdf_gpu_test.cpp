// The shared BRDF header evaluated on the GPU (shaders/test/brdf_grid.comp) agrees with its C++ build and
// stays finite and non-negative over a grid that includes the hard cases, for both BRDFs.
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "brdf.h"
#include "brdf_grid.h"
#include "vk/commands.hpp"
#include "vk/pipeline.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using shader::BrdfGridInput;
using shader::BrdfGridOutput;

glm::vec3 direction(float theta, float phi) {
  return {std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
}

std::vector<BrdfGridInput> makeGrid() {
  const glm::vec3 up(0, 1, 0);
  const std::vector<glm::vec3> normals = {up,       -up, glm::vec3(0), up * 1e-20f, glm::normalize(glm::vec3(0.3f, 1, 0.1f)),
                                          up * 3.0f};
  // Polar angles include 0, grazing (90°), just past grazing and below the surface.
  const std::vector<float> thetas = {0.0f, 0.3f, 0.8f, 1.2f, 1.5f, 1.5707f, 1.5708f, 1.5709f, 1.7f, 2.5f, 3.14159f};
  const std::vector<float> roughness = {0.0f, 1e-4f, 0.01f, 0.1f, 0.5f, 1.0f};
  const std::vector<float> metalness = {0.0f, 0.5f, 1.0f};
  std::vector<BrdfGridInput> grid;
  for (int brdf : {BRDF_BECKMANN, BRDF_GGX})
    for (const glm::vec3& n : normals)
      for (float tv : thetas)
        for (float tl : thetas)
          for (float phi : {0.0f, 1.0f, 3.14159265f})  // phi = pi with tv = tl makes v = -l mirrored
            for (float r : roughness)
              for (float m : metalness) {
                BrdfGridInput in{};
                in.n = glm::vec4(n, 0);
                in.v = glm::vec4(direction(tv, 0.0f), 0);
                in.l = glm::vec4(direction(tl, phi), 0);
                in.baseColor = glm::vec4(0.9f, 0.5f, 0.2f, 0);
                in.params = glm::vec4(r, m, float(brdf), 0);
                in.lightColor = glm::vec4(1.0f);
                in.ambient = glm::vec4(0.02f);
                in.emissive = glm::vec4(0.0f);
                grid.push_back(in);
              }
  return grid;
}

using test::VulkanTest;

TEST_F(VulkanTest, GpuBrdfIsFiniteNonNegativeAndMatchesCpu) {
  const std::vector<BrdfGridInput> grid = makeGrid();
  const VkDeviceSize inBytes = grid.size() * sizeof(BrdfGridInput), outBytes = grid.size() * sizeof(BrdfGridOutput);
  vk::Buffer in(*ctx, inBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUse::Upload, "brdf grid in");
  vk::Buffer out(*ctx, outBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUse::Readback, "brdf grid out");
  std::memcpy(in.mapped(), grid.data(), inBytes);
  in.flush();
  vk::LayoutOptions options;
  options.pushDescriptorSets = {0};
  vk::Pipeline p = vk::makeComputePipeline(*ctx, vk::loadShader("brdf_grid.comp"), options);
  vk::submitAndWait(*ctx, [&](VkCommandBuffer cb) {
    p.bind(cb);
    vk::DescriptorWriter(*ctx, p.layout, 0, VK_NULL_HANDLE)
        .buffer(BRDF_GRID_BINDING_IN, in.handle())
        .buffer(BRDF_GRID_BINDING_OUT, out.handle())
        .push(cb, p);
    p.dispatch(cb, uint32_t(grid.size()));
    vk::bufferBarrier(cb, vk::kComputeWrite, vk::kHostRead);
  });
  out.invalidate();
  const auto* gpu = static_cast<const BrdfGridOutput*>(out.mapped());
  double worst = 0;
  size_t worstAt = 0;
  for (size_t i = 0; i < grid.size(); ++i) {
    const BrdfGridInput& a = grid[i];
    const int brdf = int(a.params.z);
    const shader::BrdfTerms t =
        shader::brdfTerms(brdf, glm::vec3(a.n), glm::vec3(a.v), glm::vec3(a.l), glm::vec3(a.baseColor), a.params.x, a.params.y);
    const glm::vec3 L =
        shader::shadePbr(brdf, glm::vec3(a.n), glm::vec3(a.v), glm::vec3(a.l), glm::vec3(a.lightColor), glm::vec3(a.ambient),
                         glm::vec3(a.baseColor), a.params.x, a.params.y, glm::vec3(a.emissive));
    const float cpu[] = {t.D,         t.G,          t.F.x,        t.F.y,        t.F.z, t.diffuse.x, t.diffuse.y,
                         t.diffuse.z, t.specular.x, t.specular.y, t.specular.z, L.x,   L.y,         L.z};
    const BrdfGridOutput& g = gpu[i];
    const float got[] = {g.DG.x,      g.DG.y,       g.F.x,        g.F.y,        g.F.z,        g.diffuse.x,  g.diffuse.y,
                         g.diffuse.z, g.specular.x, g.specular.y, g.specular.z, g.radiance.x, g.radiance.y, g.radiance.z};
    for (int k = 0; k < 14; ++k) {
      ASSERT_TRUE(std::isfinite(got[k]) && got[k] >= 0.0f) << "GPU value " << k << " = " << got[k] << " at grid " << i;
      // exp and sqrt may differ by a few ulp on the GPU; Vulkan allows that. Relative 1e-3 plus a tiny floor.
      const double err = std::abs(double(got[k]) - cpu[k]) / (std::abs(double(cpu[k])) + 1e-4);
      if (err > worst) worst = err, worstAt = i;
    }
  }
  RecordProperty("max_relative_error", std::to_string(worst));
  std::printf("GPU vs CPU BRDF over %zu inputs: max relative error %.3g (input %zu)\n", grid.size(), worst, worstAt);
  EXPECT_LT(worst, 1e-3);
}

}  // namespace
}  // namespace rtr
