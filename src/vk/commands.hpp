#pragma once
// Command recording helpers: one-shot submission, synchronization2 barriers, and GPU timestamps.
#include <functional>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "vk/resources.hpp"

namespace rtr::vk {

class Context;

// Records `record` into a fresh command buffer and submits it, without waiting: done() polls, wait()
// blocks; the destructor waits (the command buffer must not be freed while it runs).
class Submission {
 public:
  Submission(const Context& ctx, const std::function<void(VkCommandBuffer)>& record);
  Submission(Submission&&) = default;
  ~Submission();
  bool done() const;
  void wait() const;

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  CommandPool pool_;
  Fence fence_;
};

// Records `record` into a fresh command buffer, submits it and waits for it to finish.
void submitAndWait(const Context& ctx, const std::function<void(VkCommandBuffer)>& record);

struct ImageBarrier {
  VkImage image = VK_NULL_HANDLE;
  VkImageLayout oldLayout = VK_IMAGE_LAYOUT_UNDEFINED, newLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkPipelineStageFlags2 srcStage = VK_PIPELINE_STAGE_2_NONE, dstStage = VK_PIPELINE_STAGE_2_NONE;
  VkAccessFlags2 srcAccess = VK_ACCESS_2_NONE, dstAccess = VK_ACCESS_2_NONE;
  uint32_t baseMip = 0, mipCount = VK_REMAINING_MIP_LEVELS;
  VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT;
};
void barrier(VkCommandBuffer cb, const std::vector<ImageBarrier>& images);
// A global memory barrier (buffers, and images whose layout does not change).
void memoryBarrier(VkCommandBuffer cb, VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess,
                   VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess);

// Read-back: copies level 0 of a colour image (in TRANSFER_SRC_OPTIMAL) tightly packed into `buffer` and
// makes the copy visible to the host once the submission's fence has signalled.
void copyImageToHost(VkCommandBuffer cb, VkImage image, VkExtent2D extent, VkBuffer buffer);

// Viewport and scissor covering all of `extent`.
void setFullViewport(VkCommandBuffer cb, VkExtent2D extent);
// Dynamic rendering into one colour attachment (no depth) covering `extent`, viewport and scissor set.
void beginColorRendering(VkCommandBuffer cb, VkImageView view, VkExtent2D extent, VkAttachmentLoadOp loadOp);

// Timestamps around named passes. Usage per frame: reset(cb); begin(cb); ...pass...; mark(cb, "pass"); ...
// then, once the frame's fence has signalled, results() gives each pass's time in milliseconds.
class GpuTimer {
 public:
  GpuTimer() = default;
  GpuTimer(const Context& ctx, uint32_t maxPasses);
  void reset(VkCommandBuffer cb);
  void begin(VkCommandBuffer cb);
  void mark(VkCommandBuffer cb, const std::string& pass);
  std::vector<std::pair<std::string, double>> results() const;  // empty until the first frame completed

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  double periodNs_ = 1.0;
  uint32_t capacity_ = 0;
  QueryPool pool_;
  std::vector<std::string> names_;
};

}  // namespace rtr::vk
