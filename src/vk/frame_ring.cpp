#include "vk/frame_ring.hpp"

#include <algorithm>
#include <cstdio>
#include <memory>

#include "vk/check.hpp"
#include "vk/context.hpp"

namespace rtr::vk {

UploadArena::Slice UploadArena::alloc(VkDeviceSize bytes, VkDeviceSize align, std::vector<std::function<void()>>& deletions) {
  VkDeviceSize offset = (used_ + align - 1) / align * align;
  if (!buffer_.handle() || offset + bytes > buffer_.size()) {
    if (buffer_.handle()) {  // earlier slices of this frame still live in it: freed with the frame
      flush();
      auto old = std::make_shared<Buffer>(std::move(buffer_));
      deletions.push_back([old] { old->reset(); });
    }
    capacity_ = std::max(capacity_ * 2, bytes);
    buffer_ = Buffer(*ctx_, capacity_,
                     VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                         VK_BUFFER_USAGE_VERTEX_BUFFER_BIT,
                     MemoryUse::Upload, "frame upload arena");
    offset = 0;
  }
  used_ = offset + bytes;
  return {buffer_.handle(), offset, static_cast<char*>(buffer_.mapped()) + offset};
}

void UploadArena::flush() const {
  if (buffer_.handle() && used_ > 0) buffer_.flush();
}

FrameRing::FrameRing(const Context& ctx, uint32_t framesInFlight, VkDeviceSize uploadCapacity) : ctx_(ctx) {
  VkDevice device = ctx.device();
  frames_.resize(framesInFlight);
  for (uint32_t i = 0; i < framesInFlight; ++i) {
    Frame& f = frames_[i];
    f.index = i;
    VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pi.queueFamilyIndex = ctx.queueFamily();
    VkCommandPool pool;
    VK_CHECK(vkCreateCommandPool(device, &pi, nullptr, &pool));
    f.pool = CommandPool(device, pool);
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VK_CHECK(vkAllocateCommandBuffers(device, &ai, &f.cb));
    VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    fi.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    VkFence fence;
    VK_CHECK(vkCreateFence(device, &fi, nullptr, &fence));
    f.fence = Fence(device, fence);
    VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore sem;
    VK_CHECK(vkCreateSemaphore(device, &si, nullptr, &sem));
    f.acquired = Semaphore(device, sem);
    f.arena = UploadArena(ctx, uploadCapacity);
  }
}

FrameRing::~FrameRing() { waitIdle(); }

void FrameRing::retire(Frame& f) {
  VkFence fence = f.fence;
  VK_CHECK(vkWaitForFences(ctx_.device(), 1, &fence, VK_TRUE, UINT64_MAX));
  for (auto& d : f.deletions) d();
  f.deletions.clear();
  f.arena.reset();
}

Frame& FrameRing::begin() {
  Frame& f = frames_[next_ % frames_.size()];
  retire(f);
  f.number = next_++;
  VK_CHECK(vkResetCommandBuffer(f.cb, 0));
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(f.cb, &bi));
  // The second frame: the first finds every image fresh, the second shows the steady state.
  if (f.number == 1 && barrierLogRequested()) beginBarrierLog();
  return f;
}

void FrameRing::submit(Frame& f, VkSemaphore wait, VkPipelineStageFlags2 waitStages, VkSemaphore signal) {
  VK_CHECK(vkEndCommandBuffer(f.cb));
  if (f.number == 1 && barrierLogRequested()) {
    std::fprintf(stderr, "barriers of frame 1:\n");
    for (const std::string& line : endBarrierLog()) std::fprintf(stderr, "  %s\n", line.c_str());
  }
  f.arena.flush();
  VkFence fence = f.fence;
  VK_CHECK(vkResetFences(ctx_.device(), 1, &fence));
  VkSemaphoreSubmitInfo w{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  w.semaphore = wait;
  w.stageMask = waitStages;
  VkSemaphoreSubmitInfo s{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  s.semaphore = signal;
  s.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  VkCommandBufferSubmitInfo cbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  cbi.commandBuffer = f.cb;
  VkSubmitInfo2 si{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  si.waitSemaphoreInfoCount = wait ? 1 : 0;
  si.pWaitSemaphoreInfos = &w;
  si.commandBufferInfoCount = 1;
  si.pCommandBufferInfos = &cbi;
  si.signalSemaphoreInfoCount = signal ? 1 : 0;
  si.pSignalSemaphoreInfos = &s;
  VK_CHECK(vkQueueSubmit2(ctx_.queue(), 1, &si, fence));
}

void FrameRing::waitIdle() {
  for (Frame& f : frames_) retire(f);
}

}  // namespace rtr::vk
