#include "render/transparency.hpp"

#include <algorithm>

#include "renderer.hpp"
#include "variants.h"

namespace rtr::render {
namespace {

size_t variantOf(const BlendDraw& d) { return size_t(d.textured) * 2 + size_t(d.doubleSided); }

}  // namespace

std::vector<const BlendDraw*> farthestFirst(std::span<const BlendDraw> draws, const glm::vec3& eye) {
  std::vector<const BlendDraw*> order;
  for (const BlendDraw& d : draws) order.push_back(&d);
  const auto dist = [&](const BlendDraw* d) { return glm::dot(d->item.center - eye, d->item.center - eye); };
  std::stable_sort(order.begin(), order.end(), [&](auto* a, auto* b) { return dist(a) > dist(b); });
  return order;
}

TransparencyPass::TransparencyPass(const vk::Context& ctx, const GpuScene& scene, const EnvironmentMaps* env)
    : ctx_(ctx), scene_(scene), env_(env) {
  std::vector<std::function<void()>> jobs;
  for (size_t v = 0; v < variants_.size(); ++v) {
    const bool textured = v >= 2, doubleSided = v % 2;
    if (std::none_of(scene.blendDraws().begin(), scene.blendDraws().end(), [&](const BlendDraw& d) { return variantOf(d) == v; }))
      continue;
    jobs.push_back([this, textured, doubleSided, &slot = variants_[v]] {
      vk::GraphicsDesc d;
      d.modules = {vk::loadShader("scene.vert"), vk::loadShader("pbr.frag")};  // the forward shading, BLEND variant
      d.specialization = {{VARIANT_TEXCOORDS, textured}, {VARIANT_BLEND, 1}, {VARIANT_ENV, env_ != nullptr}};
      d.cullMode = doubleSided ? VK_CULL_MODE_NONE : VK_CULL_MODE_BACK_BIT;
      d.dynamicFrontFace = true;  // mirrored instances' front faces are clockwise
      d.depthWrite = false;
      d.alphaBlend = true;
      d.colorFormats = {Renderer::kColorFormat};
      d.depthFormat = Renderer::kDepthFormat;
      vk::LayoutOptions options{.pushDescriptorSets = {0}};
      options.runtimeArrayCounts[{1, 0}] = std::max(1u, scene_.textureCount());
      slot.pipeline.emplace(vk::makeGraphicsPipeline(ctx_, d, options));
      if (slot.pipeline->layout.setCount() > 1) slot.textures = vk::DescriptorSets(ctx_, slot.pipeline->layout, 1);
    });
  }
  vk::inParallel(jobs);
}

std::vector<std::pair<const vk::PipelineLayout*, VkDescriptorSet>> TransparencyPass::textureSets() const {
  std::vector<std::pair<const vk::PipelineLayout*, VkDescriptorSet>> sets;
  for (const Variant& v : variants_)
    if (v.pipeline && v.pipeline->layout.setCount() > 1) sets.emplace_back(&v.pipeline->layout, v.textures.get(1));
  return sets;
}

void TransparencyPass::record(VkCommandBuffer cb, const vk::UploadArena::Slice& uniforms, const vk::Image& color,
                              const vk::Image& depth, VkExtent2D extent, const glm::vec3& eye, VkBuffer opaqueIds) {
  // Colour as the shading pass (or the forward pass) left it; depth as the hardware left it, or cleared
  // (never nearer than anything) where the compute rasteriser's word holds the opaque depth.
  vk::require(cb, {{color.tracked(), vk::Use::ColorAttachment, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT},
                   {depth.tracked(), vk::Use::DepthAttachment,
                    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                    opaqueIds != VK_NULL_HANDLE}});
  VkRenderingAttachmentInfo colorAtt{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  colorAtt.imageView = color.view();
  colorAtt.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  colorAtt.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
  colorAtt.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  VkRenderingAttachmentInfo depthAtt{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  depthAtt.imageView = depth.view();
  depthAtt.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
  depthAtt.loadOp = opaqueIds ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
  depthAtt.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  depthAtt.clearValue.depthStencil = {1.0f, 0};
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.renderArea = {{0, 0}, extent};
  ri.layerCount = 1;
  ri.colorAttachmentCount = 1;
  ri.pColorAttachments = &colorAtt;
  ri.pDepthAttachment = &depthAtt;
  if (opaqueIds) vk::bufferBarrier(cb, vk::kComputeWrite | vk::kFragmentWrite, vk::kFragmentRead);
  vkCmdBeginRendering(cb, &ri);
  vk::setFullViewport(cb, extent);
  const VkBuffer forward[3] = {scene_.positions(), scene_.normals(), scene_.texcoords()};
  const VkDeviceSize offsets[3] = {0, 0, 0};
  const Variant* bound = nullptr;
  for (const BlendDraw* bd : farthestFirst(scene_.blendDraws(), eye)) {
    const Variant& v = variants_[variantOf(*bd)];
    const vk::Pipeline& pl = *v.pipeline;
    if (&v != bound) {  // descriptors and streams again after a pipeline change (layouts differ)
      pl.bind(cb);
      vk::DescriptorWriter w(ctx_, pl.layout, 0, VK_NULL_HANDLE);
      w.buffer(0, uniforms.buffer, uniforms.offset, sizeof(shader::FrameUniforms))
          .buffer(1, scene_.materials())
          .buffer(2, scene_.instances());
      // glTF's streams (a scene without one: any buffer fills the binding; the draw's flags say none).
      const VkBuffer streams[] = {scene_.drawInfo(), scene_.texcoords1(), scene_.tangents(), scene_.colors(),
                                  opaqueIds ? opaqueIds : scene_.positions()};
      for (uint32_t b = 3; b <= 7; ++b) w.buffer(b, streams[b - 3] ? streams[b - 3] : scene_.positions());
      writeEnvironment(w, pl.layout, env_);
      w.push(cb, pl);
      if (pl.layout.setCount() > 1) pl.bindSet(cb, 1, v.textures.get(1));
      vkCmdBindVertexBuffers(cb, 0, bd->textured ? 3 : 2, forward, offsets);
      bound = &v;
    }
    const DrawItem& d = bd->item;
    vkCmdBindIndexBuffer(cb, d.indexType == VK_INDEX_TYPE_UINT16 ? scene_.indices16() : scene_.indices32(), 0, d.indexType);
    pl.push(cb, shader::DrawPush{d.material, opaqueIds ? extent.width : 0u});
    vkCmdSetFrontFace(cb, d.mirrored ? VK_FRONT_FACE_CLOCKWISE : VK_FRONT_FACE_COUNTER_CLOCKWISE);
    vkCmdDrawIndexed(cb, d.indexCount, 1, d.firstIndex, d.vertexOffset, d.firstInstance);
  }
  vkCmdEndRendering(cb);
}

}  // namespace rtr::render
