#pragma once
// Start-up: the phases from process start to the first frame, and the defaults chosen per device.
#include <future>
#include <string>
#include <utility>
#include <vector>

#include <vulkan/vulkan.h>

#include "render/mips.hpp"
#include "render/renderer.hpp"
#include "vk/pipeline_cache.hpp"

namespace rtr::render {

// Milliseconds since the kernel started this process (its start time has the kernel's clock-tick
// resolution, 10 ms on Linux; everything after is steady-clock exact).
double msSinceProcessStart();

// A pipelines row's name: `what` (N, H from the cache), or where the driver did not say, that it did not.
std::string pipelineRow(const std::string& what, const vk::PipelineStats& made);

// Named phases from process start to the first frame; printed with --timings. Those added with add() are
// the critical path, one after another: they should tile the time. Work run on another thread meanwhile
// is added with addBeside(): its own duration, marked "(beside ...)", left out of the sum.
class StartupTimeline {
 public:
  void add(std::string phase, double ms) { phases_.emplace_back(std::move(phase), ms), beside_.push_back(false); }
  void addBeside(const std::string& phase, double ms, const std::string& besideWhat) {
    phases_.emplace_back(phase + " (beside " + besideWhat + ")", ms), beside_.push_back(true);
  }
  const std::vector<std::pair<std::string, double>>& phases() const { return phases_; }
  // One line per phase, then the critical path's sum and the total measured on its own ("total from
  // process start").
  std::string format(double totalMs) const;

 private:
  std::vector<std::pair<std::string, double>> phases_;
  std::vector<bool> beside_;
};

// Renderer::prepare for `scene` on a thread of its own from construction, marked beside (its pipelines
// count in the cache's besideStats()): the pipelines made while the scene uploads (docs/startup.md "Phases
// side by side"). take() waits for them (rethrowing the thread's failure); the destructor waits too, so
// a failure on the caller's side never leaves the thread running into objects that are gone. `ctx` and
// `scene` must outlive it.
class PipelinesAhead {
 public:
  PipelinesAhead(const vk::Context& ctx, const Scene& scene, const RenderSettings& first, bool environment);
  ~PipelinesAhead();
  PipelinesAhead(const PipelinesAhead&) = delete;
  PipelinesAhead& operator=(const PipelinesAhead&) = delete;
  Renderer::Prepared take();

 private:
  std::future<Renderer::Prepared> made_;
};

// Per device type, what was measured fastest there (docs/startup.md). A flag overrides each choice.
struct DeviceDefaults {
  ShadingPath shading;
  MipMode mips;
  bool computeClip;  // the compute rasteriser's near-plane crossings clipped in compute, not handed to the hardware
  // The compute rasteriser's hardware|compute choice belongs in this table too, once it is measured.
  const char* why;  // one line: the device class and where the measurements are
};
DeviceDefaults deviceDefaults(VkPhysicalDeviceType type);

}  // namespace rtr::render
