// rtr-bench-cull: times the depth pyramid build and the cluster culling pass (src/render/cull.hpp) with
// GPU timestamps, min / median over --runs submissions after --warmup, for a scene's clusters seen from
// its default view (inside, for the temple) and from outside, at each --size. The depth source is cleared
// to the far plane, so every cluster that survives the frustum and cone tests runs the occlusion test (the
// pass's most work) and none is occluded: culled fractions by occlusion come from tests/render/cull_test.
// Prints a Markdown table. Headless: no window, no validation unless RTR_VALIDATION=1.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/camera.hpp"
#include "core/error.hpp"
#include "render/cull.hpp"
#include "scene/load.hpp"
#include "vk/commands.hpp"
#include "vk/context.hpp"

using namespace rtr;

namespace {

struct Times {
  double minMs = 0, medianMs = 0;
};
Times stats(std::vector<double> ms) {
  std::sort(ms.begin(), ms.end());
  return {ms.front(), ms.size() % 2 ? ms[ms.size() / 2] : 0.5 * (ms[ms.size() / 2 - 1] + ms[ms.size() / 2])};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rtr-bench-cull: depth pyramid and cluster culling timings"};
  std::string file;
  std::vector<std::string> sizes{"1920x1080", "3840x2160"};
  int warmup = 3, runs = 20;
  app.add_option("scene", file, "scene file (clusters are built at load where it has none)")->required();
  app.add_option("--size", sizes, "WxH, repeatable");
  app.add_option("--warmup", warmup);
  app.add_option("--runs", runs)->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  try {
    const Scene scene = loadScene(file);
    const std::vector<shader::GpuCluster> clusters = render::gpuClusters(scene);
    size_t triangles = 0;
    for (const Mesh& m : scene.meshes) triangles += m.triangleCount();
    vk::Context ctx(vk::optionsFromEnvironment());
    const uint32_t n = uint32_t(clusters.size());
    const size_t bytes = std::max<size_t>(4, n * sizeof(shader::GpuCluster));
    vk::Buffer stage(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUse::Upload, "clusters staging");
    vk::Buffer buf(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Device,
                   "clusters");
    std::memcpy(stage.mapped(), clusters.data(), n * sizeof(shader::GpuCluster));
    stage.flush();
    vk::submitAndWait(ctx, [&](VkCommandBuffer cb) {
      const VkBufferCopy c{0, 0, bytes};
      vkCmdCopyBuffer(cb, stage.handle(), buf.handle(), 1, &c);
      vk::bufferBarrier(cb, vk::kCopyWrite, vk::kComputeRead);
    });
    render::ClusterCuller culler(ctx, n);
    vk::Buffer back(ctx, sizeof(shader::CullCounts), VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback, "counts back");
    std::printf("%s: %zu triangles, %u clusters; device %s\n\n", file.c_str(), triangles, n, ctx.deviceName().c_str());
    std::printf(
        "| size | view | pyramid ms (min / median) | cull ms (min / median) | visible | frustum | cone | occlusion |\n|---|---|---|---|---:|---:|---:|---:|\n");
    for (const std::string& size : sizes) {
      VkExtent2D e{};
      if (std::sscanf(size.c_str(), "%ux%u", &e.width, &e.height) != 2 || !e.width || !e.height)
        throw rtr::Error("--size " + size + ": expected WxH");
      vk::Image depth(ctx,
                      {e, VK_FORMAT_R32_SFLOAT, 1, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, 0, 0, "depth"});
      vk::submitAndWait(ctx, [&](VkCommandBuffer cb) {
        vk::barrier(cb,
                    {{depth.handle(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE,
                      VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_NONE, VK_ACCESS_2_TRANSFER_WRITE_BIT}});
        const VkClearColorValue far{{1.0f, 0, 0, 0}};
        const VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        vkCmdClearColorImage(cb, depth.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &far, 1, &all);
        vk::barrier(cb, {{depth.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                          VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                          VK_ACCESS_2_SHADER_READ_BIT}});
      });
      render::DepthPyramid pyramid(ctx, e);
      const Bounds b = scene.bounds();
      const float aspect = float(e.width) / float(e.height);
      const std::vector<std::pair<const char*, CameraPose>> views = {
          {"default", scene.defaultView.value_or(frameBounds(b, Lens{}, aspect))},
          {"outside", orbitFrame(b, Lens{}, aspect, 30.0f, -25.0f)}};
      for (const auto& [name, pose] : views) {
        const Lens lens = fitDepthRange(Lens{}, b, pose);
        const render::CullCamera cam{projectionMatrix(lens, aspect) * viewMatrix(pose), pose.position, false};
        vk::GpuTimer timer(ctx, 2);
        std::vector<double> pyr, cull;
        for (int i = 0; i < warmup + runs; ++i) {
          vk::submitAndWait(ctx, [&](VkCommandBuffer cb) {
            timer.reset(cb);
            timer.begin(cb);
            pyramid.build(cb, depth.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
            timer.mark(cb, "pyramid");
            culler.record(cb, buf.handle(), n, cam, &pyramid);
            timer.mark(cb, "cull");
            const VkBufferCopy c{0, 0, sizeof(shader::CullCounts)};
            vkCmdCopyBuffer(cb, culler.counts(), back.handle(), 1, &c);
            vk::bufferBarrier(cb, vk::kCopyWrite, vk::kHostRead);
          });
          if (i < warmup) continue;
          const auto r = timer.results();
          pyr.push_back(r.at(0).second);
          cull.push_back(r.at(1).second);
        }
        back.invalidate();
        shader::CullCounts c;
        std::memcpy(&c, back.mapped(), sizeof(c));
        const Times p = stats(pyr), k = stats(cull);
        std::printf("| %s | %s | %.4f / %.4f | %.4f / %.4f | %u | %u | %u | %u |\n", size.c_str(), name, p.minMs, p.medianMs,
                    k.minMs, k.medianMs, c.listed, c.culled[0], c.culled[1], c.culled[2]);
      }
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rtr-bench-cull: %s\n", e.what());
    return 1;
  }
}
