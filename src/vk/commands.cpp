#include "vk/commands.hpp"

#include "vk/check.hpp"
#include "vk/context.hpp"

namespace rtr::vk {

Submission::Submission(const Context& ctx, const std::function<void(VkCommandBuffer)>& record) : device_(ctx.device()) {
  VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pi.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  pi.queueFamilyIndex = ctx.queueFamily();
  VkCommandPool rawPool;
  VK_CHECK(vkCreateCommandPool(device_, &pi, nullptr, &rawPool));
  pool_ = CommandPool(device_, rawPool);
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = pool_;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cb;
  VK_CHECK(vkAllocateCommandBuffers(device_, &ai, &cb));
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cb, &bi));
  record(cb);
  VK_CHECK(vkEndCommandBuffer(cb));
  VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence rawFence;
  VK_CHECK(vkCreateFence(device_, &fi, nullptr, &rawFence));
  fence_ = Fence(device_, rawFence);
  VkCommandBufferSubmitInfo cbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  cbi.commandBuffer = cb;
  VkSubmitInfo2 si{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  si.commandBufferInfoCount = 1;
  si.pCommandBufferInfos = &cbi;
  VK_CHECK(vkQueueSubmit2(ctx.queue(), 1, &si, fence_));
}

Submission::~Submission() {
  if (!fence_) return;  // moved from
  const VkFence f = fence_;
  vkWaitForFences(device_, 1, &f, VK_TRUE, UINT64_MAX);
}

bool Submission::done() const {
  const VkResult r = vkGetFenceStatus(device_, fence_);
  if (r != VK_NOT_READY) VK_CHECK(r);
  return r == VK_SUCCESS;
}

void Submission::wait() const {
  const VkFence f = fence_;
  VK_CHECK(vkWaitForFences(device_, 1, &f, VK_TRUE, UINT64_MAX));
}

void submitAndWait(const Context& ctx, const std::function<void(VkCommandBuffer)>& record) { Submission(ctx, record).wait(); }

void barrier(VkCommandBuffer cb, const std::vector<ImageBarrier>& images) {
  std::vector<VkImageMemoryBarrier2> bs;
  for (const ImageBarrier& b : images) {
    VkImageMemoryBarrier2 ib{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    ib.srcStageMask = b.srcStage;
    ib.srcAccessMask = b.srcAccess;
    ib.dstStageMask = b.dstStage;
    ib.dstAccessMask = b.dstAccess;
    ib.oldLayout = b.oldLayout;
    ib.newLayout = b.newLayout;
    ib.srcQueueFamilyIndex = ib.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    ib.image = b.image;
    ib.subresourceRange = {b.aspect, b.baseMip, b.mipCount, 0, VK_REMAINING_ARRAY_LAYERS};
    bs.push_back(ib);
  }
  VkDependencyInfo di{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  di.imageMemoryBarrierCount = uint32_t(bs.size());
  di.pImageMemoryBarriers = bs.data();
  vkCmdPipelineBarrier2(cb, &di);
}

void bufferBarrier(VkCommandBuffer cb, BufferUse before, BufferUse after) {
  VkMemoryBarrier2 mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
  mb.srcStageMask = before.stage;
  mb.srcAccessMask = before.access;
  mb.dstStageMask = after.stage;
  mb.dstAccessMask = after.access;
  VkDependencyInfo di{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  di.memoryBarrierCount = 1;
  di.pMemoryBarriers = &mb;
  vkCmdPipelineBarrier2(cb, &di);
}

GpuTimer::GpuTimer(const Context& ctx, uint32_t maxPasses)
    : device_(ctx.device()), periodNs_(ctx.timestampPeriodNs()), capacity_(maxPasses + 1) {
  VkQueryPoolCreateInfo qi{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
  qi.queryCount = capacity_;
  VkQueryPool raw;
  VK_CHECK(vkCreateQueryPool(device_, &qi, nullptr, &raw));
  pool_ = QueryPool(device_, raw);
  vkResetQueryPool(device_, raw, 0, capacity_);
}

void GpuTimer::reset(VkCommandBuffer cb) {
  vkCmdResetQueryPool(cb, pool_, 0, capacity_);
  names_.clear();
}

void GpuTimer::begin(VkCommandBuffer cb) { vkCmdWriteTimestamp2(cb, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, pool_, 0); }

void GpuTimer::mark(VkCommandBuffer cb, const std::string& pass) {
  if (names_.size() + 1 >= capacity_)
    throw Error("GpuTimer: more passes than the " + std::to_string(capacity_ - 1) + " it was made for");
  names_.push_back(pass);
  vkCmdWriteTimestamp2(cb, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, pool_, uint32_t(names_.size()));
}

std::vector<std::pair<std::string, double>> GpuTimer::results() const {
  std::vector<std::pair<std::string, double>> out;
  if (names_.empty()) return out;
  std::vector<uint64_t> ts(names_.size() + 1);
  VkResult r = vkGetQueryPoolResults(device_, pool_, 0, uint32_t(ts.size()), ts.size() * 8, ts.data(), 8, VK_QUERY_RESULT_64_BIT);
  if (r != VK_SUCCESS) return out;
  for (size_t i = 0; i < names_.size(); ++i) out.push_back({names_[i], double(ts[i + 1] - ts[i]) * periodNs_ * 1e-6});
  return out;
}

void copyImageToHost(VkCommandBuffer cb, VkImage image, VkExtent2D extent, VkBuffer buffer) {
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {extent.width, extent.height, 1};
  vkCmdCopyImageToBuffer(cb, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer, 1, &region);
  bufferBarrier(cb, kCopyWrite, kHostRead);
}

void setFullViewport(VkCommandBuffer cb, VkExtent2D extent) {
  const VkViewport vp{0, 0, float(extent.width), float(extent.height), 0.0f, 1.0f};
  const VkRect2D sc{{0, 0}, extent};
  vkCmdSetViewport(cb, 0, 1, &vp);
  vkCmdSetScissor(cb, 0, 1, &sc);
}

void beginColorRendering(VkCommandBuffer cb, VkImageView view, VkExtent2D extent, VkAttachmentLoadOp loadOp) {
  VkRenderingAttachmentInfo color{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  color.imageView = view;
  color.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  color.loadOp = loadOp;
  color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.renderArea = {{0, 0}, extent};
  ri.layerCount = 1;
  ri.colorAttachmentCount = 1;
  ri.pColorAttachments = &color;
  vkCmdBeginRendering(cb, &ri);
  setFullViewport(cb, extent);
}

}  // namespace rtr::vk
