#include "render/renderer.hpp"

#include <cstdio>
#include <cstring>

#include "core/error.hpp"
#include "vk/context.hpp"

namespace rtr::render {
namespace {

// Shader files of each scene pipeline: the vertex stage, the shaded fragment stage, the debug one.
struct StageFiles { const char* vert; const char* shaded; const char* debug; };
constexpr StageFiles kStages[kDrawKindCount] = {
    {"scene.vert", "pbr.frag", "debug.frag"},
    {"scene_untextured.vert", "pbr_untextured.frag", "debug_untextured.frag"},
    {"scene.vert", "pbr_alpha.frag", "debug_alpha.frag"},
};

// Who last used the intermediate images: the post pass reads colour in compute or fragment shaders.
constexpr VkPipelineStageFlags2 kPostReadStages = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;

}  // namespace

Renderer::Renderer(const vk::Context& ctx, const GpuScene& scene, uint32_t framesInFlight)
    : ctx_(ctx), scene_(scene), framesInFlight_(framesInFlight), post_(ctx) {
  for (uint32_t i = 0; i < framesInFlight; ++i) {
    uniforms_.emplace_back(ctx, sizeof(shader::FrameUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, vk::MemoryUse::Upload,
                           "frame uniforms");
    timers_.emplace_back(ctx, 4);
  }
  rebuildPipelines();
}

Renderer::ScenePipelines Renderer::makePipeline(DrawKind kind, bool debug) const {
  const StageFiles& f = kStages[size_t(kind)];
  vk::GraphicsDesc d;
  d.modules = {vk::loadShader(f.vert), vk::loadShader(debug ? f.debug : f.shaded)};
  d.cullMode = kind == DrawKind::AlphaMasked ? VK_CULL_MODE_NONE : VK_CULL_MODE_BACK_BIT;  // foliage is two-sided
  d.colorFormats = {kColorFormat};
  d.depthFormat = kDepthFormat;
  vk::LayoutOptions options;
  if (kind != DrawKind::Untextured) options.runtimeArrayCounts[{1, 0}] = std::max(1u, scene_.textureCount());
  ScenePipelines p;
  p.pipeline.emplace(vk::makeGraphicsPipeline(ctx_, d, options));
  const vk::PipelineLayout& layout = p.pipeline->layout;
  p.sets = vk::DescriptorSets(ctx_, layout, framesInFlight_);
  auto textures = scene_.textureDescriptors();
  for (uint32_t frame = 0; frame < framesInFlight_; ++frame) {
    vk::DescriptorWriter w(ctx_, layout, 0, p.sets.get(0, frame));
    w.buffer(0, uniforms_[frame].handle()).buffer(1, scene_.materials()).commit();
    if (layout.setCount() > 1 && !textures.empty())
      vk::DescriptorWriter(ctx_, layout, 1, p.sets.get(1, frame)).images(0, textures).commit();
  }
  return p;
}

void Renderer::rebuildPipelines() {
  // Build all first, swap after: a failure leaves the running pipelines untouched.
  std::array<ScenePipelines, kDrawKindCount> shaded, debug;
  for (size_t k = 0; k < kDrawKindCount; ++k) {
    if (!scene_.hasDraws(DrawKind(k))) continue;  // only pipelines the scene needs
    shaded[k] = makePipeline(DrawKind(k), false);
    debug[k] = makePipeline(DrawKind(k), true);
  }
  vkDeviceWaitIdle(ctx_.device());
  shaded_ = std::move(shaded);
  debug_ = std::move(debug);
}

void Renderer::createTargets(VkExtent2D extent) {
  vkDeviceWaitIdle(ctx_.device());
  color_ = vk::Image(ctx_, {extent, kColorFormat, 1,
                            VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                            0, 0, "scene colour"});
  depth_ = vk::Image(ctx_, {extent, kDepthFormat, 1, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, 0, 0, "scene depth"});
  extent_ = extent;
}

void Renderer::drawScene(VkCommandBuffer cb, uint32_t frame, bool debug) {
  auto& pipelines = debug ? debug_ : shaded_;
  // Opaque geometry first, alpha-masked last (brief 1.6).
  for (DrawKind kind : {DrawKind::Opaque, DrawKind::Untextured, DrawKind::AlphaMasked}) {
    ScenePipelines& p = pipelines[size_t(kind)];
    if (!p.pipeline) continue;
    const vk::Pipeline& pl = *p.pipeline;
    pl.bind(cb);
    for (uint32_t set = 0; set < pl.layout.setCount(); ++set) pl.bindSet(cb, set, p.sets.get(set, frame));
    VkBuffer streams[3] = {scene_.positions(), scene_.normals(), scene_.texcoords()};
    VkDeviceSize offsets[3] = {0, 0, 0};
    vkCmdBindVertexBuffers(cb, 0, kind == DrawKind::Untextured ? 2 : 3, streams, offsets);
    VkIndexType bound = VK_INDEX_TYPE_MAX_ENUM;
    for (const DrawItem& d : scene_.draws(kind)) {
      if (d.indexType != bound) {
        vkCmdBindIndexBuffer(cb, d.indexType == VK_INDEX_TYPE_UINT16 ? scene_.indices16() : scene_.indices32(), 0, d.indexType);
        bound = d.indexType;
      }
      shader::DrawPush push{d.material};
      pl.push(cb, push);
      vkCmdDrawIndexed(cb, d.indexCount, 1, d.firstIndex, d.vertexOffset, 0);
    }
  }
}

void Renderer::record(VkCommandBuffer cb, uint32_t frame, const CameraPose& pose, const Lens& lens,
                      const RenderSettings& s, const RenderTarget& target) {
  if (target.extent.width != extent_.width || target.extent.height != extent_.height) createTargets(target.extent);
  const float aspect = float(target.extent.width) / float(target.extent.height);

  shader::FrameUniforms u{};
  u.view = viewMatrix(pose);
  u.viewProj = projectionMatrix(lens, aspect) * u.view;
  u.cameraPos = glm::vec4(pose.position, 1.0f);
  u.lightPos = glm::vec4(s.lightPos, 1.0f);
  u.lightColor = glm::vec4(s.lightColor, s.inverseSquareFalloff ? 1.0f : 0.0f);
  u.ambient = glm::vec4(s.ambient, 0.0f);
  u.params = glm::vec4(float(s.mode), s.lodBias, lens.zNear, lens.zFar);
  std::memcpy(uniforms_[frame].mapped(), &u, sizeof u);
  uniforms_[frame].flush();

  vk::GpuTimer& timer = timers_[frame];
  timer.reset(cb);
  timer.begin(cb);
  // The previous frame's post pass may still read the colour image: wait for it (write-after-read),
  // and for the previous depth writes; old contents are discarded.
  vk::barrier(cb, {{color_.handle(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                    kPostReadStages, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_NONE,
                    VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT},
                   {depth_.handle(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                    VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT, VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT,
                    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                    0, 1, VK_IMAGE_ASPECT_DEPTH_BIT}});

  VkRenderingAttachmentInfo colorAtt{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  colorAtt.imageView = color_.view();
  colorAtt.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  colorAtt.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  colorAtt.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  colorAtt.clearValue.color = {{0.0f, 0.0f, 0.0f, 1.0f}};
  VkRenderingAttachmentInfo depthAtt{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  depthAtt.imageView = depth_.view();
  depthAtt.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
  depthAtt.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  depthAtt.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  depthAtt.clearValue.depthStencil = {1.0f, 0};
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.renderArea = {{0, 0}, target.extent};
  ri.layerCount = 1;
  ri.colorAttachmentCount = 1;
  ri.pColorAttachments = &colorAtt;
  ri.pDepthAttachment = &depthAtt;
  vkCmdBeginRendering(cb, &ri);
  VkViewport vp{0, 0, float(target.extent.width), float(target.extent.height), 0.0f, 1.0f};
  VkRect2D sc{{0, 0}, target.extent};
  vkCmdSetViewport(cb, 0, 1, &vp);
  vkCmdSetScissor(cb, 0, 1, &sc);
  drawScene(cb, frame, s.mode != VIEW_SHADED);
  vkCmdEndRendering(cb);
  timer.mark(cb, "scene");

  vk::barrier(cb, {{color_.handle(), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                    VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, kPostReadStages,
                    VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT}});
  post_.record(cb, color_.view(), target.image, target.view, target.format, target.extent, s.mosaic, target.finalLayout);
  timer.mark(cb, "post");
}

}  // namespace rtr::render
