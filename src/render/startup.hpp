#pragma once
// Start-up: the phases from process start to the first frame, and the defaults chosen per device.
#include <string>
#include <utility>
#include <vector>

#include <vulkan/vulkan.h>

#include "render/mips.hpp"
#include "render/renderer.hpp"

namespace rtr::render {

// Milliseconds since the kernel started this process (its start time has the kernel's clock-tick
// resolution, 10 ms on Linux; everything after is steady-clock exact).
double msSinceProcessStart();

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

// Per device type, what was measured fastest there (docs/startup.md). A flag overrides each choice.
struct DeviceDefaults {
  ShadingPath shading;
  MipMode mips;
  bool computeClip;       // the compute rasteriser's near-plane crossings clipped in compute, not handed to the hardware
  GeometryUpload upload;  // Direct or Staged (RTR_UPLOAD overrides: render::geometryUpload)
  // The compute rasteriser's hardware|compute choice belongs in this table too, once it is measured.
  const char* why;  // one line: the device class and where the measurements are
};
DeviceDefaults deviceDefaults(VkPhysicalDeviceType type);

}  // namespace rtr::render
