#include "render/staging_ring.hpp"

#include "vk/context.hpp"

namespace rtr::render {

StagingRing::StagingRing(const vk::Context& ctx, size_t slotBytes, uint32_t slots)
    : ctx_(ctx), slotBytes_((std::max<size_t>(slotBytes, 1) + 255) & ~size_t(255)), reading_(std::max(slots, 1u)) {}

StagingRing::~StagingRing() { waitAll(); }

void StagingRing::waitAll() {
  for (auto& s : reading_) s.reset();  // a Submission waits for its fence when it goes
}

uint32_t StagingRing::acquire(size_t bytes) {
  if (bytes > slotBytes_) {
    waitAll();
    buffer_ = {};
    slotBytes_ = (bytes + 255) & ~size_t(255);
  }
  // Host-cached memory where the device has it: zstd reads back what it wrote (its matches), which
  // write-combined memory makes slow; the device's copies read it either way.
  if (!buffer_.handle())
    buffer_ = vk::Buffer(ctx_, slotBytes_ * reading_.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUse::Readback,
                         "texture staging ring"),
    ++allocations_;
  const uint32_t slot = next_;
  next_ = (next_ + 1) % uint32_t(reading_.size());
  reading_[slot].reset();
  return slot;
}

const vk::Submission& StagingRing::submit(uint32_t slot, const std::function<void(VkCommandBuffer)>& record) {
  buffer_.flush();
  ++submissions_;
  return reading_[slot].emplace(ctx_, record);
}

}  // namespace rtr::render
