#include "render/staging_ring.hpp"

#include <chrono>

#include "vk/context.hpp"

namespace rtr::render {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

}  // namespace

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
  auto t = Clock::now();
  if (bytes > slotBytes_) {
    waitAll();
    buffer_ = {};
    slotBytes_ = (bytes + 255) & ~size_t(255);
  }
  waitMs_ += msSince(t);
  allocate();
  const uint32_t slot = next_;
  next_ = (next_ + 1) % uint32_t(reading_.size());
  t = Clock::now();
  reading_[slot].reset();
  waitMs_ += msSince(t);
  return slot;
}

void StagingRing::allocate() {
  if (buffer_.handle()) return;
  const auto t = Clock::now();
  buffer_ = vk::Buffer(ctx_, slotBytes_ * reading_.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, use_, name_), ++allocations_;
  allocMs_ += msSince(t);
}

const vk::Submission& StagingRing::submit(uint32_t slot, const std::function<void(VkCommandBuffer)>& record) {
  const auto t = Clock::now();
  buffer_.flush();
  ++submissions_;
  const vk::Submission& s = reading_[slot].emplace(ctx_, record);
  submitMs_ += msSince(t);
  return s;
}

}  // namespace rtr::render
