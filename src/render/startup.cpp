#include "render/startup.hpp"

#include <time.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace rtr::render {

double msSinceProcessStart() {
  // Field 22 of /proc/self/stat: the start time in clock ticks since boot (after the command name,
  // which may hold spaces, hence the search for its closing parenthesis).
  std::ifstream in("/proc/self/stat");
  std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t close = stat.rfind(')');
  if (close == std::string::npos) return 0;
  std::istringstream fields(stat.substr(close + 2));
  std::string field;
  unsigned long long ticks = 0;
  for (int i = 3; i <= 22 && fields >> field; ++i)
    if (i == 22) ticks = std::stoull(field);
  timespec now{};
  clock_gettime(CLOCK_BOOTTIME, &now);
  const double startMs = double(ticks) * 1000.0 / double(sysconf(_SC_CLK_TCK));
  return double(now.tv_sec) * 1e3 + double(now.tv_nsec) * 1e-6 - startMs;
}

std::string pipelineRow(const std::string& what, const vk::PipelineStats& made) {
  return what + " (" + std::to_string(made.created) +
         (made.reported == made.created ? ", " + std::to_string(made.cacheHits) + " from the cache)"
                                        : ", cache hits not reported)");
}

std::string StartupTimeline::format(double totalMs) const {
  std::string out = "start-up phases (ms):\n";
  char line[256];
  double sum = 0;
  for (size_t i = 0; i < phases_.size(); ++i) {
    std::snprintf(line, sizeof line, "  %-58s %9.1f\n", phases_[i].first.c_str(), phases_[i].second);
    out += line;
    if (!beside_[i]) sum += phases_[i].second;
  }
  std::snprintf(line, sizeof line, "  %-58s %9.1f\n  %-58s %9.1f\n", "sum of the critical path's phases", sum,
                "total from process start", totalMs);
  return out + line;
}

PipelinesAhead::PipelinesAhead(const vk::Context& ctx, const Scene& scene, const RenderSettings& first, bool environment)
    : made_(std::async(std::launch::async, [&ctx, &scene, first, environment] {
        const vk::PipelineCache::BesideThread beside;
        return Renderer::prepare(ctx, sceneKinds(scene), first, environment);
      })) {}

PipelinesAhead::~PipelinesAhead() {
  if (made_.valid()) made_.wait();
}

Renderer::Prepared PipelinesAhead::take() { return made_.get(); }

DeviceDefaults deviceDefaults(VkPhysicalDeviceType type) {
  // A CPU rasteriser (lavapipe) pays the same for fragment and compute work, so the visibility path's
  // extra pass only costs; its blit chain beats the compute mips on large textures, and small ones' chains
  // are cheapest made on the CPU (no pipeline or blit shader to compile): Auto. Clipping in compute runs a
  // 128-thread workgroup per crossing triangle: 0.019 ms against the hardware hand-off's 0.122 on the H100
  // at 4K, but 2.6-3.9 ms against 0.2 on lavapipe (docs/raster.md).
  if (type == VK_PHYSICAL_DEVICE_TYPE_CPU)
    return {ShadingPath::Forward, MipMode::Auto, false, "a CPU device, measured fastest there"};
  return {ShadingPath::Visibility, MipMode::Compute, true, "a GPU, measured fastest with a discrete one"};
}

}  // namespace rtr::render
