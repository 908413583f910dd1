#pragma once
// The driver's pipeline cache, kept on disk between runs so that a second start compiles nothing.
// One file per device and driver: its name and its header carry the vendor and device ids, the driver
// version and the device's pipelineCacheUUID, and a checksum over the driver's bytes. A file that is
// short, damaged or from another device or driver is ignored with one note and replaced on the next
// save: the driver never sees bytes that were not checked. Counts every pipeline created through it.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

namespace rtr::vk {

struct PipelineStats {
  uint32_t created = 0;    // pipelines created
  uint32_t cacheHits = 0;  // of those, found whole in the cache (creation feedback says so)
  uint32_t reported = 0;   // of those, with valid creation feedback (a driver may give none)
  double ms = 0;           // wall time while at least one was being made (reflection, layouts, modules,
                           // the driver): pipelines made on parallel threads are not counted twice
};

// $XDG_CACHE_HOME/rtr, else $HOME/.cache/rtr; empty when neither is set.
std::filesystem::path defaultPipelineCacheDir();

class PipelineCache {
 public:
  // dir empty: an in-memory cache only (nothing read or written).
  PipelineCache(VkDevice device, const VkPhysicalDeviceProperties& props, std::filesystem::path dir);
  ~PipelineCache();
  PipelineCache(const PipelineCache&) = delete;
  PipelineCache& operator=(const PipelineCache&) = delete;

  VkPipelineCache handle() const { return cache_; }
  const std::filesystem::path& file() const { return file_; }  // empty when not on disk
  bool loaded() const { return loaded_; }                      // a valid file was read

  // Around each pipeline's creation, from any thread: begin(), then end() with its creation feedback
  // (nullptr when the creation failed), both on the same thread.
  void begin();
  void end(const VkPipelineCreationFeedback* feedback);
  // Pipelines made on a thread marked beside (a BesideThread alive on it, or a job inParallel runs for
  // one) count in besideStats(), all others in stats(): a timeline takes out of its phases only what its
  // own thread made, and shows the pipelines made beside them as a row of their own (docs/startup.md).
  PipelineStats stats() const;
  PipelineStats besideStats() const;
  class BesideThread {
   public:
    BesideThread();
    ~BesideThread();
    BesideThread(const BesideThread&) = delete;
    BesideThread& operator=(const BesideThread&) = delete;
  };
  static bool onBesideThread();

  // Writes the cache atomically when it holds more than was read; a failure is a note, not an error
  // (the cache only saves time). Called by the destructor too.
  void save();

 private:
  VkDevice device_;
  VkPhysicalDeviceProperties props_;
  std::filesystem::path file_;
  VkPipelineCache cache_ = VK_NULL_HANDLE;
  bool loaded_ = false;
  std::vector<uint8_t> loadedBytes_;  // the driver's bytes as read, to skip saving what is unchanged
  mutable std::mutex mutex_;
  struct Account {
    PipelineStats stats;
    uint32_t active = 0;  // creations under way
    std::chrono::steady_clock::time_point busySince;
  };
  Account main_, beside_;
};

}  // namespace rtr::vk
