#include "vk/pipeline_executables.hpp"

#include <cstdio>
#include <cstring>

#include "vk/check.hpp"

namespace rtr::vk {
namespace {

std::string valueText(const VkPipelineExecutableStatisticKHR& s) {
  char text[64];
  switch (s.format) {
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR: return s.value.b32 ? "true" : "false";
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR:
      std::snprintf(text, sizeof text, "%lld", static_cast<long long>(s.value.i64));
      break;
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR:
      std::snprintf(text, sizeof text, "%llu", static_cast<unsigned long long>(s.value.u64));
      break;
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_FLOAT64_KHR: std::snprintf(text, sizeof text, "%g", s.value.f64); break;
    default: return "?";
  }
  return text;
}

}  // namespace

PipelineExecutableLog::PipelineExecutableLog(VkDevice device, bool on, bool capture)
    : device_(device), on_(on), capture_(on && capture) {
  if (!capture_) return;
  properties_ = reinterpret_cast<PFN_vkGetPipelineExecutablePropertiesKHR>(
      vkGetDeviceProcAddr(device_, "vkGetPipelineExecutablePropertiesKHR"));
  statistics_ = reinterpret_cast<PFN_vkGetPipelineExecutableStatisticsKHR>(
      vkGetDeviceProcAddr(device_, "vkGetPipelineExecutableStatisticsKHR"));
  if (!properties_ || !statistics_) throw Error("VK_KHR_pipeline_executable_properties enabled without its functions");
}

void PipelineExecutableLog::record(const std::string& name, VkPipeline pipeline) {
  if (!on_) return;
  PipelineReport report{name, {}};
  uint32_t n = 0;
  VkPipelineInfoKHR info{VK_STRUCTURE_TYPE_PIPELINE_INFO_KHR};
  info.pipeline = pipeline;
  if (capture_) VK_CHECK(properties_(device_, &info, &n, nullptr));
  std::vector<VkPipelineExecutablePropertiesKHR> props(n, {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_PROPERTIES_KHR});
  if (n) VK_CHECK(properties_(device_, &info, &n, props.data()));
  for (uint32_t i = 0; i < n; ++i) {
    PipelineExecutable e{props[i].name, props[i].description, props[i].subgroupSize, {}};
    VkPipelineExecutableInfoKHR ei{VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR};
    ei.pipeline = pipeline;
    ei.executableIndex = i;
    uint32_t m = 0;
    VK_CHECK(statistics_(device_, &ei, &m, nullptr));
    // Zeroed whole: `{sType}` sets only the value union's first 32 bits, and NVIDIA 580's "Local Memory
    // Size" (UINT64) read 2^36 + n from such records, as if the driver wrote only the low half.
    std::vector<VkPipelineExecutableStatisticKHR> stats(m);
    for (VkPipelineExecutableStatisticKHR& s : stats) {
      std::memset(&s, 0, sizeof s);
      s.sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR;
    }
    VK_CHECK(statistics_(device_, &ei, &m, stats.data()));
    for (const auto& s : stats) e.statistics.push_back({s.name, valueText(s)});
    report.executables.push_back(std::move(e));
  }
  std::lock_guard lock(mutex_);
  reports_.push_back(std::move(report));
}

std::vector<PipelineReport> PipelineExecutableLog::reports() const {
  std::lock_guard lock(mutex_);
  return reports_;
}

std::string formatReports(const std::vector<PipelineReport>& reports) {
  std::string out;
  for (const PipelineReport& r : reports) {
    out += "pipeline " + r.pipeline + "\n";
    for (const PipelineExecutable& e : r.executables) {
      out += "  " + e.name + " (" + e.description + "), subgroup " + std::to_string(e.subgroupSize) + "\n";
      for (const ExecutableStatistic& s : e.statistics) out += "    " + s.name + ": " + s.value + "\n";
    }
  }
  return out;
}

}  // namespace rtr::vk
