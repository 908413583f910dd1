#include "render/staging_ring.hpp"

#include "vk/context.hpp"

namespace rtr::render {

StagingRing::StagingRing(const vk::Context& ctx, size_t slotBytes, uint32_t slots, vk::MemoryUse use, const char* name)
    : ctx_(ctx),
      slotBytes_((std::max<size_t>(slotBytes, 1) + 255) & ~size_t(255)),
      use_(use),
      name_(name),
      reading_(std::max(slots, 1u)) {}

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
  if (!buffer_.handle())
    buffer_ = vk::Buffer(ctx_, slotBytes_ * reading_.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, use_, name_), ++allocations_;
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
