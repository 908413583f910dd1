#include "imgui_pass.hpp"

#include <cstring>

#include <imgui.h>

#include "vk/check.hpp"
#include "vk/context.hpp"

namespace rtr::view {
namespace {

struct Push {  // imgui.vert's push constants
  float scale[2], translate[2];
  uint32_t vertexBase;
};
static_assert(sizeof(ImDrawVert) == 20 && sizeof(ImDrawIdx) == 2, "imgui.vert reads 20-byte vertices, 16-bit indices");

}  // namespace

ImGuiPass::ImGuiPass(const vk::Context& ctx, uint32_t framesInFlight) : ctx_(ctx), drawn_(framesInFlight, false) {
  for (uint32_t i = 0; i < framesInFlight; ++i) timers_.emplace_back(ctx, 1);
  unsigned char* pixels = nullptr;
  int w = 0, h = 0;
  ImGui::GetIO().Fonts->GetTexDataAsRGBA32(&pixels, &w, &h);
  font_ = vk::Image(ctx, {{uint32_t(w), uint32_t(h)},
                          VK_FORMAT_R8G8B8A8_UNORM,
                          1,
                          VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                          0,
                          0,
                          "imgui font"});
  const size_t bytes = size_t(w) * h * 4;
  vk::Buffer stage(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUse::Upload, "imgui font staging");
  std::memcpy(stage.mapped(), pixels, bytes);
  stage.flush();
  vk::submitAndWait(ctx, [&](VkCommandBuffer cb) {
    vk::barrier(cb, {{font_.handle(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE,
                      VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE, VK_ACCESS_2_TRANSFER_WRITE_BIT}});
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {uint32_t(w), uint32_t(h), 1};
    vkCmdCopyBufferToImage(cb, stage.handle(), font_.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    vk::barrier(cb, {{font_.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                      VK_PIPELINE_STAGE_2_COPY_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                      VK_ACCESS_2_SHADER_SAMPLED_READ_BIT}});
  });
  VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  si.magFilter = si.minFilter = VK_FILTER_LINEAR;
  si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  VkSampler raw;
  VK_CHECK(vkCreateSampler(ctx.device(), &si, nullptr, &raw));
  sampler_ = vk::Sampler(ctx.device(), raw);
}

vk::Pipeline ImGuiPass::makePipeline(VkFormat format) const {
  vk::GraphicsDesc d;
  d.modules = {vk::loadShader("imgui.vert"), vk::loadShader("imgui.frag")};
  d.cullMode = VK_CULL_MODE_NONE;
  d.depthTest = d.depthWrite = false;
  d.alphaBlend = true;
  d.colorFormats = {format};
  return vk::makeGraphicsPipeline(ctx_, d, {.pushDescriptorSets = {0}});
}

void ImGuiPass::rebuildPipelines() {
  std::map<VkFormat, vk::Pipeline> fresh;
  for (const auto& [format, p] : pipelines_) fresh.emplace(format, makePipeline(format));
  VK_CHECK(vkDeviceWaitIdle(ctx_.device()));  // the old pipelines may still be in use by frames in flight
  pipelines_ = std::move(fresh);
}

std::optional<double> ImGuiPass::gpuMs(uint32_t frame) const {
  if (!drawn_[frame]) return std::nullopt;
  const auto r = timers_[frame].results();
  if (r.empty()) return std::nullopt;
  return r[0].second;
}

void ImGuiPass::record(vk::Frame& frame, const ImDrawData& data, vk::TrackedImage image, VkImageView view, VkFormat format,
                       VkExtent2D extent) {
  drawn_[frame.index] = false;
  if (data.TotalVtxCount == 0) return;
  // One vertex and one index array for all lists, in this frame's arena.
  const VkDeviceSize align = ctx_.properties().limits.minStorageBufferOffsetAlignment;
  const VkDeviceSize vBytes = VkDeviceSize(data.TotalVtxCount) * sizeof(ImDrawVert);
  const VkDeviceSize iBytes = (VkDeviceSize(data.TotalIdxCount) * sizeof(ImDrawIdx) + 3) & ~VkDeviceSize(3);
  const vk::UploadArena::Slice verts = frame.upload(vBytes, align), indices = frame.upload(iBytes, align);
  auto* v = static_cast<uint8_t*>(verts.data);
  auto* i = static_cast<uint8_t*>(indices.data);
  for (int n = 0; n < data.CmdListsCount; ++n) {
    const ImDrawList* list = data.CmdLists[n];
    std::memcpy(v, list->VtxBuffer.Data, list->VtxBuffer.Size * sizeof(ImDrawVert));
    std::memcpy(i, list->IdxBuffer.Data, list->IdxBuffer.Size * sizeof(ImDrawIdx));
    v += list->VtxBuffer.Size * sizeof(ImDrawVert);
    i += list->IdxBuffer.Size * sizeof(ImDrawIdx);
  }

  auto it = pipelines_.find(format);
  if (it == pipelines_.end()) it = pipelines_.emplace(format, makePipeline(format)).first;
  const vk::Pipeline& p = it->second;
  vk::GpuTimer& timer = timers_[frame.index];
  timer.reset(frame.cb);
  vk::require(frame.cb, image, vk::Use::ColorAttachment, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT);
  timer.begin(frame.cb);
  vk::beginColorRendering(frame.cb, view, extent, VK_ATTACHMENT_LOAD_OP_LOAD);
  p.bind(frame.cb);
  vk::DescriptorWriter(ctx_, p.layout, 0, VK_NULL_HANDLE)
      .buffer(0, verts.buffer, verts.offset, vBytes)
      .buffer(1, indices.buffer, indices.offset, iBytes)
      .image(2, font_.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, sampler_)
      .push(frame.cb, p);
  // ImGui's coordinates are logical pixels from DisplayPos; the target has FramebufferScale times as many.
  Push push{{2.0f / data.DisplaySize.x, 2.0f / data.DisplaySize.y},
            {-1.0f - data.DisplayPos.x * 2.0f / data.DisplaySize.x, -1.0f - data.DisplayPos.y * 2.0f / data.DisplaySize.y},
            0};
  const ImVec2 clipOff = data.DisplayPos, clipScale = data.FramebufferScale;
  uint32_t vertexBase = 0, indexBase = 0;
  for (int n = 0; n < data.CmdListsCount; ++n) {
    const ImDrawList* list = data.CmdLists[n];
    for (const ImDrawCmd& cmd : list->CmdBuffer) {
      if (cmd.UserCallback) continue;  // the panel uses none
      const float x0 = std::max(0.0f, (cmd.ClipRect.x - clipOff.x) * clipScale.x);
      const float y0 = std::max(0.0f, (cmd.ClipRect.y - clipOff.y) * clipScale.y);
      const float x1 = std::min(float(extent.width), (cmd.ClipRect.z - clipOff.x) * clipScale.x);
      const float y1 = std::min(float(extent.height), (cmd.ClipRect.w - clipOff.y) * clipScale.y);
      if (x1 <= x0 || y1 <= y0) continue;
      const VkRect2D scissor{{int32_t(x0), int32_t(y0)}, {uint32_t(x1 - x0), uint32_t(y1 - y0)}};
      vkCmdSetScissor(frame.cb, 0, 1, &scissor);
      push.vertexBase = vertexBase + cmd.VtxOffset;
      p.push(frame.cb, push);
      vkCmdDraw(frame.cb, cmd.ElemCount, 1, indexBase + cmd.IdxOffset, 0);
    }
    vertexBase += uint32_t(list->VtxBuffer.Size);
    indexBase += uint32_t(list->IdxBuffer.Size);
  }
  vkCmdEndRendering(frame.cb);
  timer.mark(frame.cb, "panel");
  drawn_[frame.index] = true;
}

}  // namespace rtr::view
