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

// Buffers are not tracked one by one: a pass states what touched them before and what touches them next,
// `vk::bufferBarrier(cb, before, after)`, from the named uses below (combined with |). It records one
// global memory barrier (all buffers, and images whose layout does not change).
struct BufferUse {
  VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_NONE;
  VkAccessFlags2 access = VK_ACCESS_2_NONE;
};
constexpr BufferUse operator|(BufferUse a, BufferUse b) { return {a.stage | b.stage, a.access | b.access}; }
constexpr VkAccessFlags2 kShaderReadWrite = VK_ACCESS_2_SHADER_READ_BIT | VK_ACCESS_2_SHADER_WRITE_BIT;
constexpr BufferUse kComputeRead{VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_READ_BIT};
constexpr BufferUse kComputeWrite{VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_WRITE_BIT};
constexpr BufferUse kComputeReadWrite{VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, kShaderReadWrite};
constexpr BufferUse kVertexRead{VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT, VK_ACCESS_2_SHADER_READ_BIT};
constexpr BufferUse kVertexReadWrite{VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT, kShaderReadWrite};
constexpr BufferUse kFragmentRead{VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_READ_BIT};
constexpr BufferUse kFragmentWrite{VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_WRITE_BIT};
constexpr BufferUse kFragmentReadWrite{VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, kShaderReadWrite};
constexpr BufferUse kIndirectRead{VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT, VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT};
constexpr BufferUse kVertexInput{VK_PIPELINE_STAGE_2_VERTEX_INPUT_BIT | VK_PIPELINE_STAGE_2_INDEX_INPUT_BIT,
                                 VK_ACCESS_2_VERTEX_ATTRIBUTE_READ_BIT | VK_ACCESS_2_INDEX_READ_BIT};
constexpr BufferUse kCopyRead{VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT};
constexpr BufferUse kCopyWrite{VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
constexpr BufferUse kTransferWrite{VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};  // fill, update
constexpr BufferUse kHostRead{VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT};
void bufferBarrier(VkCommandBuffer cb, BufferUse before, BufferUse after);

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
