#pragma once
// Staging memory for uploads (the textures', a Staged geometry upload's), allocated once and reused batch after batch (docs/startup.md,
// "Staging ring"): one persistently mapped host buffer cut into slots; a batch's texels are written into a
// slot (unpacked or copied on all cores) and copied to its images by one submission, and a slot is written
// again only once the submission that read it has completed. A load allocates no staging memory per
// texture, and touches only the ring's pages, however many textures pass through it.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "vk/commands.hpp"
#include "vk/resources.hpp"

namespace rtr::render {

class StagingRing {
 public:
  // `slots` slots of `slotBytes` each (rounded up to 256), made on first use: host-cached memory for the
  // textures (Readback: zstd reads back what it wrote, which write-combined memory makes slow), Upload for
  // data written once.
  StagingRing(const vk::Context& ctx, size_t slotBytes, uint32_t slots, vk::MemoryUse use = vk::MemoryUse::Readback,
              const char* name = "texture staging ring");
  ~StagingRing();  // waits for the submissions still reading it
  StagingRing(const StagingRing&) = delete;
  StagingRing& operator=(const StagingRing&) = delete;

  // The next slot, at least `bytes` long, once the submission that last read it has completed. A batch
  // larger than a slot (one texture over the budget) makes the ring that much larger: every submission
  // is waited for and the buffer made again.
  uint32_t acquire(size_t bytes);
  uint8_t* data(uint32_t slot) const { return static_cast<uint8_t*>(buffer_.mapped()) + offset(slot); }
  VkDeviceSize offset(uint32_t slot) const { return VkDeviceSize(slot) * slotBytes_; }
  VkBuffer buffer() const { return buffer_.handle(); }
  // Flushes the slot's writes and submits `record` (its copies read the slot); the slot is held until the
  // submission completed.
  const vk::Submission& submit(uint32_t slot, const std::function<void(VkCommandBuffer)>& record);
  void waitAll();
  // For a caller that fills every slot from several threads and tracks the submissions reading them
  // itself (GpuScene's geometry; acquire() and submit() are then not used): the buffer made now, and the
  // host's writes made visible before such a submission.
  void allocate();
  void flush() const { buffer_.flush(); }
  uint32_t slots() const { return uint32_t(reading_.size()); }

  size_t slotBytes() const { return slotBytes_; }
  uint32_t allocations() const { return allocations_; }  // buffers made (1 unless a batch outgrew a slot)
  uint32_t submissions() const { return submissions_; }
  // Where the caller's time went (ms): making the buffer, waiting in acquire() for a slot's submission,
  // recording and submitting (rtr-bench-upload and GpuSceneStats report them).
  double allocationMs() const { return allocMs_; }
  double waitMs() const { return waitMs_; }
  double submitMs() const { return submitMs_; }

 private:
  const vk::Context& ctx_;
  size_t slotBytes_;
  vk::MemoryUse use_;
  const char* name_;
  vk::Buffer buffer_;
  std::vector<std::optional<vk::Submission>> reading_;  // per slot: the submission that last read it
  uint32_t next_ = 0, allocations_ = 0, submissions_ = 0;
  double allocMs_ = 0, waitMs_ = 0, submitMs_ = 0;
};

}  // namespace rtr::render
