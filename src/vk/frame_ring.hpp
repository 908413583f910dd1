#pragma once
// Frames in flight. Each frame owns what the GPU may still be using while the CPU records the next one:
// its command buffer, its fence, its acquire semaphore, an upload arena for this frame's CPU->GPU copies,
// and a deletion queue. Both are recycled only once the frame's fence has signalled, so host writes never
// touch memory an earlier, unfinished frame still reads (synchronization validation cannot see those).
#include <functional>
#include <vector>

#include <vulkan/vulkan.h>

#include "vk/resources.hpp"

namespace rtr::vk {

class Context;

// Host-visible memory handed out front to back during one frame; reset when the frame's fence signalled.
// Grows by retiring the full buffer to the frame's deletion queue (earlier slices of this frame still use it).
class UploadArena {
 public:
  struct Slice {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceSize offset = 0;
    void* data = nullptr;  // host pointer to `bytes` writable bytes
  };
  UploadArena() = default;
  UploadArena(const Context& ctx, VkDeviceSize capacity) : ctx_(&ctx), capacity_(capacity) {}
  Slice alloc(VkDeviceSize bytes, VkDeviceSize align, std::vector<std::function<void()>>& deletions);
  void flush() const;  // before the frame is submitted
  void reset() { used_ = 0; }
  VkDeviceSize used() const { return used_; }  // bytes handed out this frame

 private:
  const Context* ctx_ = nullptr;
  VkDeviceSize capacity_ = 0, used_ = 0;
  Buffer buffer_;
};

struct Frame {
  uint32_t index = 0;   // which of the ring's frames: picks per-frame descriptor sets, uniforms, timers
  uint64_t number = 0;  // frames begun before this one
  VkCommandBuffer cb = VK_NULL_HANDLE;
  // Bytes for this frame's CPU->GPU copies; valid until the frame's fence signals.
  UploadArena::Slice upload(VkDeviceSize bytes, VkDeviceSize align = 16) { return arena.alloc(bytes, align, deletions); }
  // Runs `f` once the GPU has finished this frame (to free what its commands use).
  void defer(std::function<void()> f) { deletions.push_back(std::move(f)); }

  CommandPool pool;
  Fence fence;
  Semaphore acquired;  // signalled by the swapchain's acquire (window frames only)
  UploadArena arena;
  std::vector<std::function<void()>> deletions;
};

class FrameRing {
 public:
  FrameRing(const Context& ctx, uint32_t framesInFlight, VkDeviceSize uploadCapacity = 1 << 20);
  ~FrameRing();  // waits for the device
  FrameRing(const FrameRing&) = delete;
  FrameRing& operator=(const FrameRing&) = delete;

  uint32_t size() const { return uint32_t(frames_.size()); }
  // Waits for the next frame's previous use to finish, runs its deletion queue, resets its arena and
  // begins its command buffer.
  Frame& begin();
  // Ends and submits the frame's commands, signalling its fence. `wait`/`signal` are optional semaphores
  // (the swapchain's acquire and render-done).
  void submit(Frame& frame, VkSemaphore wait = VK_NULL_HANDLE, VkPipelineStageFlags2 waitStages = 0,
              VkSemaphore signal = VK_NULL_HANDLE);
  // Waits for every frame and runs all deletion queues.
  void waitIdle();

 private:
  void retire(Frame& f);
  const Context& ctx_;
  std::vector<Frame> frames_;
  uint64_t next_ = 0;
};

}  // namespace rtr::vk
