#pragma once
// What the driver made of each pipeline (VK_KHR_pipeline_executable_properties): per executable (a
// shader stage as the driver compiled it) the statistics it names, such as registers, shared memory,
// spills and instruction counts. Names and units are the driver's own. Captured only when the context was
// made with ContextOptions::pipelineStatistics on a device that has the extension: capturing may slow
// creation and changes the pipeline cache's keys.
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

namespace rtr::vk {

struct ExecutableStatistic {
  std::string name, value;  // value as text (bool, integer or float)
};

struct PipelineExecutable {
  std::string name, description;
  uint32_t subgroupSize = 0;
  std::vector<ExecutableStatistic> statistics;
};

struct PipelineReport {
  std::string pipeline;  // its shaders' names and specialization constants
  std::vector<PipelineExecutable> executables;
};

// Every pipeline created through vk/pipeline.hpp while the log is on, in creation order; thread-safe.
// On a device without the extension it lists the pipelines' names only.
class PipelineExecutableLog {
 public:
  PipelineExecutableLog(VkDevice device, bool on, bool capture);
  bool capturing() const { return capture_; }
  // Reads the statistics of `pipeline` (made with VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR).
  void record(const std::string& name, VkPipeline pipeline);
  std::vector<PipelineReport> reports() const;

 private:
  VkDevice device_;
  bool on_, capture_;
  PFN_vkGetPipelineExecutablePropertiesKHR properties_ = nullptr;
  PFN_vkGetPipelineExecutableStatisticsKHR statistics_ = nullptr;
  mutable std::mutex mutex_;
  std::vector<PipelineReport> reports_;
};

// One line per pipeline, then one per executable and one per statistic, indented.
std::string formatReports(const std::vector<PipelineReport>& reports);

}  // namespace rtr::vk
