#include "vk/image_state.hpp"

#include <cstdlib>
#include <cstring>
#include <optional>

namespace rtr::vk {
namespace {

struct UseInfo {
  VkImageLayout layout;
  VkAccessFlags2 access;
  bool write;
};

UseInfo info(Use use, bool discard) {
  switch (use) {
    case Use::ColorAttachment:
      return {VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
              discard ? VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT
                      : VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
              true};
    case Use::DepthAttachment:
      return {VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, true};
    case Use::Sampled: return {VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, false};
    case Use::Storage: return {VK_IMAGE_LAYOUT_GENERAL, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, true};
    case Use::CopySrc: return {VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_2_TRANSFER_READ_BIT, false};
    case Use::CopyDst: return {VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_ACCESS_2_TRANSFER_WRITE_BIT, true};
    case Use::Present: return {VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_ACCESS_2_NONE, false};
  }
  return {};
}

std::optional<std::vector<std::string>> gLog;

const char* layoutName(VkImageLayout l) {
  switch (l) {
    case VK_IMAGE_LAYOUT_UNDEFINED: return "UNDEFINED";
    case VK_IMAGE_LAYOUT_GENERAL: return "GENERAL";
    case VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL: return "COLOR_ATTACHMENT";
    case VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL: return "DEPTH_ATTACHMENT";
    case VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL: return "SHADER_READ_ONLY";
    case VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL: return "TRANSFER_SRC";
    case VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL: return "TRANSFER_DST";
    case VK_IMAGE_LAYOUT_PRESENT_SRC_KHR: return "PRESENT_SRC";
    default: return "?";
  }
}

template <class Bits>
std::string bitNames(uint64_t mask, const Bits& names) {
  if (mask == 0) return "NONE";
  std::string out;
  for (const auto& [bit, name] : names)
    if (mask & bit) out += (out.empty() ? "" : "|") + std::string(name), mask &= ~bit;
  if (mask) out += (out.empty() ? "" : "|") + std::to_string(mask);
  return out;
}

std::string stageNames(VkPipelineStageFlags2 s) {
  static const std::pair<uint64_t, const char*> names[] = {
      {VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, "ALL_COMMANDS"},
      {VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT, "EARLY_FRAGMENT_TESTS"},
      {VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT, "LATE_FRAGMENT_TESTS"},
      {VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, "FRAGMENT_SHADER"},
      {VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, "COLOR_ATTACHMENT_OUTPUT"},
      {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, "COMPUTE_SHADER"},
      {VK_PIPELINE_STAGE_2_COPY_BIT, "COPY"},
  };
  return bitNames(s, names);
}

std::string accessNames(VkAccessFlags2 a) {
  static const std::pair<uint64_t, const char*> names[] = {
      {VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT, "COLOR_ATTACHMENT_READ"},
      {VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, "COLOR_ATTACHMENT_WRITE"},
      {VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, "DEPTH_STENCIL_ATTACHMENT_WRITE"},
      {VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, "SHADER_SAMPLED_READ"},
      {VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, "SHADER_STORAGE_WRITE"},
      {VK_ACCESS_2_TRANSFER_READ_BIT, "TRANSFER_READ"},
      {VK_ACCESS_2_TRANSFER_WRITE_BIT, "TRANSFER_WRITE"},
  };
  return bitNames(a, names);
}

}  // namespace

void require(VkCommandBuffer cb, std::initializer_list<Requirement> reqs) {
  std::vector<VkImageMemoryBarrier2> bs;
  std::vector<const char*> names;  // for the log
  for (const Requirement& r : reqs) {
    ImageState& s = *r.image.state;
    const UseInfo u = info(r.use, r.discard);
    const bool sameLayout = u.layout == s.layout && !r.discard;
    if (!u.write && sameLayout) {
      // A read: nothing to wait for when these stages already waited for the last write (or none was made).
      const bool waited = (r.stage & ~s.readStages) == 0 || (s.writeStage == 0 && s.writeAccess == 0);
      if (!waited) {
        VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
        b.srcStageMask = s.writeStage;
        b.srcAccessMask = s.writeAccess;
        b.dstStageMask = r.stage;
        b.dstAccessMask = u.access;
        b.oldLayout = b.newLayout = s.layout;
        b.image = r.image.image;
        b.subresourceRange = {r.image.aspect, 0, VK_REMAINING_MIP_LEVELS, 0, VK_REMAINING_ARRAY_LAYERS};
        bs.push_back(b);
        names.push_back(r.image.name);
      }
      s.readStages |= r.stage;
      continue;
    }
    // A write or a layout change (itself a write): after the readers since the last write, which already
    // waited for it (their stages chain to it, its memory was made available), or else after that write.
    VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    b.srcStageMask = s.readStages ? s.readStages : s.writeStage;
    b.srcAccessMask = s.readStages ? VK_ACCESS_2_NONE : s.writeAccess;
    b.dstStageMask = r.stage;
    b.dstAccessMask = u.access;
    b.oldLayout = r.discard ? VK_IMAGE_LAYOUT_UNDEFINED : s.layout;
    b.newLayout = u.layout;
    b.image = r.image.image;
    b.subresourceRange = {r.image.aspect, 0, VK_REMAINING_MIP_LEVELS, 0, VK_REMAINING_ARRAY_LAYERS};
    bs.push_back(b);
    names.push_back(r.image.name);
    if (u.write) s = {u.layout, r.stage, u.access & ~(VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT), 0};
    else s = {u.layout, r.stage, VK_ACCESS_2_NONE, r.stage};  // the layout change made the old write visible
  }
  if (bs.empty()) return;
  if (gLog)
    for (size_t i = 0; i < bs.size(); ++i) {
      const VkImageMemoryBarrier2& b = bs[i];
      gLog->push_back(std::string(names[i]) + ": " + layoutName(b.oldLayout) + " -> " + layoutName(b.newLayout) + ", " +
                      stageNames(b.srcStageMask) + "/" + accessNames(b.srcAccessMask) + " -> " + stageNames(b.dstStageMask) +
                      "/" + accessNames(b.dstAccessMask));
    }
  VkDependencyInfo di{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  di.imageMemoryBarrierCount = uint32_t(bs.size());
  di.pImageMemoryBarriers = bs.data();
  vkCmdPipelineBarrier2(cb, &di);
}

void beginBarrierLog() { gLog.emplace(); }

std::vector<std::string> endBarrierLog() {
  std::vector<std::string> out = gLog ? std::move(*gLog) : std::vector<std::string>{};
  gLog.reset();
  return out;
}

bool barrierLogRequested() {
  const char* v = std::getenv("RTR_PRINT_BARRIERS");
  return v && std::strcmp(v, "1") == 0;
}

}  // namespace rtr::vk
