#pragma once
// The window's start-up phases, as headless --timings prints them: each runs from the end of the one
// before, less the pipelines it made (one row of their own), so the rows tile the time to the first frame
// on screen; work on other threads meanwhile has rows of its own, marked beside (not in the sum).
#include <chrono>
#include <cstdio>
#include <string>

#include "render/startup.hpp"
#include "vk/context.hpp"
#include "vk/pipeline_cache.hpp"

namespace rtr::view {

class StartupClock {
 public:
  StartupClock() { timeline_.add("process start to the viewer (exec, libraries, options)", render::msSinceProcessStart()); }
  // From here on, pipeline creation on `ctx` is taken out of the phases.
  void watch(const vk::Context& ctx) { ctx_ = &ctx; }
  // `lessMs`: of its time, what has a row of its own (add()).
  void phase(const std::string& name, double lessMs = 0) {
    const double p = ctx_ ? ctx_->pipelineCache().stats().ms : 0;
    timeline_.add(name, std::chrono::duration<double, std::milli>(Clock::now() - start_).count() - (p - pipelineMs_) - lessMs);
    pipelineMs_ = p;
    start_ = Clock::now();
  }
  void add(const std::string& name, double ms) { timeline_.add(name, ms); }
  // Work that ran on another thread meanwhile: its own duration, marked, not in the sum.
  void beside(const std::string& name, double ms, const std::string& besideWhat) { timeline_.addBeside(name, ms, besideWhat); }
  // The first frame is on screen: its phase and the pipelines' row; printed when `print`.
  void firstFrame(bool print) {
    phase("first frame (record, GPU, present)");
    totalMs_ = render::msSinceProcessStart();
    const vk::PipelineStats ps = ctx_->pipelineCache().stats();
    timeline_.add(render::pipelineRow("pipeline creation", ps), ps.ms);
    if (print) std::fprintf(stderr, "rtr-view: %s", timeline_.format(totalMs_).c_str());
    done_ = true;
  }
  // The phases once the first frame is on screen (the panel shows them), else none.
  const std::vector<std::pair<std::string, double>>* phases() const { return done_ ? &timeline_.phases() : nullptr; }
  double totalMs() const { return totalMs_; }

 private:
  using Clock = std::chrono::steady_clock;
  render::StartupTimeline timeline_;
  const vk::Context* ctx_ = nullptr;
  Clock::time_point start_ = Clock::now();
  double pipelineMs_ = 0, totalMs_ = 0;
  bool done_ = false;
};

}  // namespace rtr::view
