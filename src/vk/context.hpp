#pragma once
// The Vulkan instance, device, queue and memory allocator. Knows no window: a windowed app passes the
// instance extensions its surface needs and creates the surface itself.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

typedef struct VmaAllocator_T* VmaAllocator;

namespace rtr::vk {

class PipelineCache;
class PipelineExecutableLog;

struct ContextOptions {
  bool validation = false;                      // Khronos validation layer + debug messenger (fails loudly if missing)
  bool syncValidation = false;                  // synchronization validation (tests turn it on)
  std::string device;                           // "" = best; else an index ("1") or a substring of the device name
  std::vector<const char*> instanceExtensions;  // e.g. those GLFW needs for a surface
  bool presentation = false;                    // enable VK_KHR_swapchain on the device
  std::filesystem::path pipelineCacheDir;       // where the pipeline cache file lives; empty: not on disk
  bool pipelineStatistics = false;              // log every pipeline made, with its statistics where the device has them
};

// Options from the environment: RTR_VALIDATION=1 enables validation (+ sync validation),
// RTR_DEVICE picks the device. Debug builds validate by default. RTR_PIPELINE_CACHE=DIR keeps the
// pipeline cache in DIR, =0 or =off keeps none; unset, the user's cache folder (the tests' environment
// sets it off: they never touch it unless they name a folder).
ContextOptions optionsFromEnvironment();

class Context {
 public:
  explicit Context(const ContextOptions& options);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physicalDevice() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queueFamily() const { return queueFamily_; }
  VmaAllocator allocator() const { return allocator_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  std::string deviceName() const { return properties_.deviceName; }
  std::string driverInfo() const { return driverInfo_; }
  bool validationEnabled() const { return messenger_ != VK_NULL_HANDLE; }
  float timestampPeriodNs() const { return properties_.limits.timestampPeriod; }

  // Validation messages (warnings and errors) seen so far; tests assert this stays 0.
  static uint32_t validationMessageCount();
  static void resetValidationMessageCount();

  PFN_vkCmdPushDescriptorSetKHR pushDescriptorFn() const { return pushDescriptorFn_; }
  VkPhysicalDeviceType deviceType() const { return properties_.deviceType; }
  // Runtime descriptor arrays may have elements written that no pending command buffer uses
  // (descriptorBindingUpdateUnusedWhilePending, enabled where supported): textures arriving while frames run.
  bool updateUnusedWhilePending() const { return updateUnusedWhilePending_; }
  // The largest device-local memory heap, in bytes: what one scene and its targets must fit in.
  VkDeviceSize deviceHeapBytes() const;
  // Every pipeline is created through it (vk/pipeline.cpp), which also counts them and their time.
  PipelineCache& pipelineCache() const { return *pipelineCache_; }
  // Whether the device has VK_KHR_pipeline_executable_properties; the log captures only where it does and
  // the options asked for it.
  bool pipelineStatisticsSupported() const { return statisticsSupported_; }
  PipelineExecutableLog& pipelineExecutables() const { return *executables_; }

  // Names an object in validation messages and debuggers (no-op without validation).
  void setName(uint64_t handle, VkObjectType type, const char* name) const;

 private:
  void release();

  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  std::string driverInfo_;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queueFamily_ = 0;
  VmaAllocator allocator_ = nullptr;
  std::unique_ptr<PipelineCache> pipelineCache_;
  std::unique_ptr<PipelineExecutableLog> executables_;
  bool statisticsSupported_ = false;
  PFN_vkCmdPushDescriptorSetKHR pushDescriptorFn_ = nullptr;
  bool updateUnusedWhilePending_ = false;
};

}  // namespace rtr::vk
