#include "render/renderer.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <utility>

#include "core/error.hpp"
#include "raster.h"
#include "variants.h"
#include "vk/check.hpp"
#include "vk/context.hpp"

namespace rtr::render {
namespace {

// Every draw kind in one place: its variant of the scene shaders (specialization constants, variants.h),
// whose visibility pipeline draws it, and its cull mode. The vertex streams bound are the variant's
// reflected inputs. Rows are in draw order: opaque geometry first, alpha-masked last (brief 1.6).
struct KindInfo {
  bool textured, alphaMasked;
  DrawKind visAs;        // whose visibility pipeline draws this kind (untextured: the opaque one, positions only)
  VkCullModeFlags cull;  // foliage (alpha-masked, two-sided) is not culled
};
constexpr KindInfo kKinds[kDrawKindCount] = {
    {true, false, DrawKind::Opaque, VK_CULL_MODE_BACK_BIT},
    {false, false, DrawKind::Opaque, VK_CULL_MODE_BACK_BIT},
    {true, true, DrawKind::AlphaMasked, VK_CULL_MODE_NONE},
};
// The scene passes' sources, one per pass (shaders/*.vert, *.frag, *.comp); variants by constants.
constexpr const char* kSceneVert = "scene.vert";
constexpr const char* kFrag[] = {"pbr.frag", "debug.frag"};  // by PipelineSet: kShaded, kDebug

}  // namespace

std::vector<const DrawItem*> nearestFirst(std::span<const DrawItem> draws, const glm::vec3& eye) {
  std::vector<const DrawItem*> order;
  for (const DrawItem& d : draws) order.push_back(&d);
  const auto dist = [&](const DrawItem* d) { return glm::dot(d->center - eye, d->center - eye); };
  std::stable_sort(order.begin(), order.end(), [&](auto* a, auto* b) { return dist(a) < dist(b); });
  return order;
}

Renderer::Choice::Choice(const vk::Context& ctx, const SceneKinds& k) : kinds(k) {
  VkPhysicalDeviceFeatures features{};
  vkGetPhysicalDeviceFeatures(ctx.physicalDevice(), &features);  // the context enables it where supported
  cpuDevice = ctx.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  canHardware = features.geometryShader;
  canCompute = ComputeRaster::supported(ctx) && k.clusterIdsFit;
  if (k.visIds > GpuScene::kMaxVisIds)
    visibilityRefusal = "the scene's " + std::to_string(k.visIds) +
                        " triangle ids (each instance's triangles, hierarchy included) do not fit the visibility "
                        "buffer's 32 bits";
  else if (!canHardware && !canCompute) visibilityRefusal = "the device has neither rasteriser of the visibility path";
  canUseVisibility = k.instances > 0 && visibilityRefusal.empty();
}

ShadingPath Renderer::Choice::pathFor(const RenderSettings& s) const {
  return s.shading == ShadingPath::Visibility && s.mode == VIEW_SHADED && canUseVisibility ? ShadingPath::Visibility
                                                                                           : ShadingPath::Forward;
}

RasterPath Renderer::Choice::rasterFor(const RenderSettings& s) const {
  // The default per device type, the faster one measured (docs/raster.md): compute on GPUs; on a CPU
  // device (lavapipe) compute from about 100 k triangles, where the two cross.
  const bool computeFaster = !cpuDevice || kinds.triangles >= 100000;
  const RasterPath wanted = s.raster != RasterPath::Auto ? s.raster : computeFaster ? RasterPath::Compute : RasterPath::Hardware;
  if (wanted == RasterPath::Compute) return canCompute ? RasterPath::Compute : RasterPath::Hardware;
  return canHardware ? RasterPath::Hardware : RasterPath::Compute;
}

Renderer::Plan Renderer::plan(const Choice& c, const RenderSettings& s, bool environment, bool readSceneColor) {
  Plan p{};
  p.visibility = c.pathFor(s) == ShadingPath::Visibility;
  p.raster = p.visibility ? c.rasterFor(s) : RasterPath::Auto;
  p.set = p.visibility ? kVisibility : s.mode == VIEW_SHADED ? kShaded : kDebug;
  // The shading pass writes the target's bytes itself where nothing else reads the linear image: the
  // post pass would only copy and encode it (mosaic off), no transparent pass blends into it, no caller reads it.
  p.display = p.visibility && s.mosaic == MosaicMode::Off && !c.kinds.blended && !readSceneColor;
  p.backdrop = environment && p.set == kShaded && s.backdropBlur >= 0.0f;
  return p;
}

std::array<bool, kDrawKindCount> Renderer::kindsOf(const SceneKinds& kinds, PipelineSet set) {
  std::array<bool, kDrawKindCount> needed{};
  for (size_t k = 0; k < kDrawKindCount; ++k)  // visibility: by any kind drawn with this one's pipeline
    needed[set == kVisibility ? size_t(kKinds[k].visAs) : k] |= kinds.draws[k];
  return needed;
}

vk::Pipeline Renderer::makeScenePipeline(const vk::Context& ctx, const SceneKinds& kinds, PipelineSet set, size_t kind,
                                         bool environment) {
  const KindInfo& info = kKinds[kind];
  vk::GraphicsDesc d;
  if (set == kVisibility) {
    d.modules = {vk::loadShader("vis.vert"), vk::loadShader("vis.frag")};
    d.specialization = {{VARIANT_ALPHA_MASK, info.alphaMasked}};
  } else {
    d.modules = {vk::loadShader(kSceneVert), vk::loadShader(kFrag[set])};
    d.specialization = {{VARIANT_TEXCOORDS, info.textured}, {VARIANT_ALPHA_MASK, info.alphaMasked}, {VARIANT_ENV, environment}};
  }
  d.cullMode = info.cull;
  d.dynamicFrontFace = true;  // per draw: mirrored instances' front faces are clockwise
  d.colorFormats = {set == kVisibility ? kVisFormat : kColorFormat};
  d.depthFormat = kDepthFormat;
  vk::LayoutOptions options;
  options.runtimeArrayCounts[{1, 0}] = std::max(1u, kinds.textures);
  return vk::makeGraphicsPipeline(ctx, d, options);
}

// RTR_SHADE_IDENTITY=0: the instances' transforms applied even where all are the identity (comparing the two).
static bool shadeIdentity() {
  const char* v = std::getenv("RTR_SHADE_IDENTITY");
  return !v || std::strcmp(v, "0") != 0;
}

vk::Pipeline Renderer::makeShadePipeline(const vk::Context& ctx, const SceneKinds& kinds, bool fromBuffer, bool display,
                                         bool environment) {
  vk::LayoutOptions options{.pushDescriptorSets = {0}};
  options.runtimeArrayCounts[{1, 0}] = std::max(1u, kinds.textures);
  return vk::makeComputePipeline(ctx, vk::loadShader("vis_shade.comp"), options,
                                 {{VARIANT_TEXCOORDS, kinds.texcoords},
                                  {VARIANT_VIS_BUFFER, fromBuffer},
                                  {VARIANT_ENV, environment},
                                  {VARIANT_MATERIAL_EXTRAS, kinds.materialExtras},
                                  {VARIANT_DISPLAY, display},
                                  {VARIANT_IDENTITY, kinds.identityInstances && shadeIdentity()}});
}

vk::Pipeline Renderer::makeBackdrop(const vk::Context& ctx) {
  return vk::makeComputePipeline(ctx, vk::loadShader("env_backdrop.comp"), {.pushDescriptorSets = {0}});
}

Renderer::Prepared Renderer::prepare(const vk::Context& ctx, const SceneKinds& kinds, const RenderSettings& first,
                                     bool environment) {
  Prepared p;
  p.kinds = kinds;
  p.environment = environment;
  const Plan f = plan(Choice(ctx, kinds), first, environment, false);
  std::vector<std::function<void()>> jobs;
  if (f.raster == RasterPath::Compute) {
    jobs.push_back([&] { p.raster = ComputeRaster::makePipelines(ctx, kinds); });
  } else {
    const std::array<bool, kDrawKindCount> needed = kindsOf(kinds, f.set);
    for (size_t k = 0; k < kDrawKindCount; ++k)
      if (needed[k])
        jobs.push_back([&, k] { p.scene[f.set * kDrawKindCount + k] = makeScenePipeline(ctx, kinds, f.set, k, environment); });
  }
  if (f.visibility)
    jobs.push_back([&] {
      p.shade[2 * size_t(f.raster) + f.display] =
          makeShadePipeline(ctx, kinds, f.raster == RasterPath::Compute, f.display, environment);
    });
  if (f.backdrop) jobs.push_back([&] { p.backdrop = makeBackdrop(ctx); });
  if (!f.display && first.mosaic != MosaicMode::Graphics) jobs.push_back([&] { p.mosaic = MosaicPass::makeCompute(ctx); });
  vk::inParallel(jobs);
  return p;
}

Renderer::Renderer(const vk::Context& ctx, const GpuScene& scene, uint32_t framesInFlight, Prepared prepared)
    : ctx_(ctx),
      scene_(scene),
      framesInFlight_(framesInFlight),
      arrivalsSeen_(scene.textureArrivals()),
      choice_(ctx, scene.kinds()),
      // Made for another scene's kinds (a caller's mistake): none is taken, all are made here.
      prepared_(prepared.kinds == choice_.kinds ? std::move(prepared) : Prepared{}),
      post_(ctx, std::exchange(prepared_.mosaic, std::nullopt)) {
  makeTextureInfos();
  for (uint32_t i = 0; i < framesInFlight; ++i) {
    timers_.emplace_back(ctx, 15);  // at most: ComputeRaster::record's eleven passes, shade, transparent, post
  }
  if (!scene.blendDraws().empty()) {
    transparency_.emplace(ctx, scene);
    writeTextureSets();
  }
}

Renderer::Renderer(const vk::Context& ctx, const GpuScene& scene, uint32_t framesInFlight)
    : Renderer(ctx, scene, framesInFlight, Prepared{}) {}

ShadingPath Renderer::pathFor(const RenderSettings& s) const { return choice_.pathFor(s); }

RasterPath Renderer::rasterFor(const RenderSettings& s) const { return choice_.rasterFor(s); }

std::optional<vk::Pipeline> Renderer::takePrepared(std::optional<vk::Pipeline>& slot, bool dependsOnEnvironment) {
  if (dependsOnEnvironment && prepared_.environment != (env_ != nullptr)) return std::nullopt;
  return std::exchange(slot, std::nullopt);
}

Renderer::ScenePipelines Renderer::withSets(vk::Pipeline pipeline) const {
  ScenePipelines p;
  p.pipeline.emplace(std::move(pipeline));
  const vk::PipelineLayout& layout = p.pipeline->layout;
  p.sets = vk::DescriptorSets(ctx_, layout, framesInFlight_);
  for (uint32_t frame = 0; frame < framesInFlight_; ++frame) {
    if (layout.setCount() == 0) break;
    // Binding 0 (the uniforms) is written per frame: they live in the frame's upload arena.
    vk::DescriptorWriter w(ctx_, layout, 0, p.sets.get(0, frame));
    if (layout.hasBinding(0, 1)) w.buffer(1, scene_.materials());
    if (layout.hasBinding(0, 2)) w.buffer(2, scene_.instances());
    // glTF's streams (a scene without one: any buffer fills the binding; the draw's flags say none).
    const VkBuffer streams[] = {scene_.drawInfo(), scene_.texcoords1(), scene_.tangents(), scene_.colors()};
    for (uint32_t b = 3; b <= 6; ++b)
      if (layout.hasBinding(0, b)) w.buffer(b, streams[b - 3] ? streams[b - 3] : scene_.positions());
    writeEnvironment(w, layout, env_.get());
    w.commit();
    if (layout.setCount() > 1) writeTextures(layout, p.sets.get(1, frame));
  }
  return p;
}

Renderer::KindPipelines Renderer::makePipelines(PipelineSet set) {
  // The kinds' pipelines are made in parallel, only those the scene needs (those prepared are taken).
  KindPipelines out;
  const std::array<bool, kDrawKindCount> needed = kindsOf(choice_.kinds, set);
  std::array<std::optional<vk::Pipeline>, kDrawKindCount> made;
  for (size_t k = 0; k < kDrawKindCount; ++k)
    if (needed[k]) made[k] = takePrepared(prepared_.scene[set * kDrawKindCount + k], set != kVisibility);
  std::vector<std::function<void()>> jobs;
  for (size_t k = 0; k < kDrawKindCount; ++k)
    if (needed[k])
      jobs.push_back([this, set, k, &made, &slot = out[k]] {
        slot = withSets(made[k] ? std::move(*made[k]) : makeScenePipeline(ctx_, choice_.kinds, set, k, env_ != nullptr));
      });
  vk::inParallel(jobs);
  return out;
}

Renderer::VisShade Renderer::makeShade(bool fromBuffer, bool display) {
  VisShade v;
  std::optional<vk::Pipeline> made =
      takePrepared(prepared_.shade[2 * size_t(fromBuffer ? RasterPath::Compute : RasterPath::Hardware) + display], true);
  v.pipeline.emplace(made ? std::move(*made) : makeShadePipeline(ctx_, choice_.kinds, fromBuffer, display, env_ != nullptr));
  if (v.pipeline->layout.setCount() > 1) {
    v.textures = vk::DescriptorSets(ctx_, v.pipeline->layout, 1);
    writeTextures(v.pipeline->layout, v.textures.get(1));
  }
  return v;
}

void Renderer::setEnvironment(std::shared_ptr<const EnvironmentMaps> env) {
  VK_CHECK(vkDeviceWaitIdle(ctx_.device()));
  env_ = std::move(env);
  pipelines_[kShaded].reset();
  pipelines_[kDebug].reset();  // the environment's views
  shade_ = {};
  backdrop_.reset();
  if (transparency_) {  // blended surfaces are lit by the environment too
    transparency_.reset();
    transparency_.emplace(ctx_, scene_, env_.get());
    for (const auto& [layout, set] : transparency_->textureSets()) writeTextures(*layout, set);
  }
}

void Renderer::backdropPass(VkCommandBuffer cb) {
  if (!backdrop_) backdrop_ = takePrepared(prepared_.backdrop, false);
  if (!backdrop_) backdrop_.emplace(makeBackdrop(ctx_));
  vk::require(cb, color_.tracked(), vk::Use::Storage, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
  backdrop_->bind(cb);
  vk::DescriptorWriter w(ctx_, backdrop_->layout, 0, VK_NULL_HANDLE);
  w.buffer(0, uniforms_.buffer, uniforms_.offset, sizeof(shader::FrameUniforms)).image(8, color_.view(), VK_IMAGE_LAYOUT_GENERAL);
  writeEnvironment(w, backdrop_->layout, env_.get());
  w.push(cb, *backdrop_);
  backdrop_->dispatch(cb, extent_.width, extent_.height);
}

void Renderer::ensurePipelines(PipelineSet set) {
  if (pipelines_[set]) return;
  pipelines_[set] = makePipelines(set);
}

void Renderer::rebuildPipelines() {
  // Build all that exist first, swap after: a failure leaves the running pipelines untouched.
  prepared_ = {};  // made from the shaders of before
  std::array<std::optional<KindPipelines>, kPipelineSetCount> fresh;
  std::array<VisShade, 6> shade;
  std::optional<ComputeRaster> raster;
  for (int set = 0; set < kPipelineSetCount; ++set)
    if (pipelines_[set]) fresh[set] = makePipelines(PipelineSet(set));
  for (size_t i = 0; i < shade.size(); ++i)
    if (shade_[i].pipeline) shade[i] = makeShade(RasterPath(i / 2) == RasterPath::Compute, i % 2 != 0);
  if (raster_) raster.emplace(ctx_, scene_, framesInFlight_);
  std::optional<vk::Pipeline> backdrop;
  if (backdrop_) backdrop.emplace(makeBackdrop(ctx_));
  std::optional<TransparencyPass> transparency;
  if (transparency_) transparency.emplace(ctx_, scene_, env_.get());
  vkDeviceWaitIdle(ctx_.device());
  pipelines_ = std::move(fresh);
  shade_ = std::move(shade);
  backdrop_ = std::move(backdrop);
  if (transparency) {
    transparency_.reset();
    transparency_.emplace(std::move(*transparency));
    writeTextureSets();
  }
  if (raster) {
    raster->resize(extent_);
    raster_.reset();
    raster_.emplace(std::move(*raster));
    for (const auto& [layout, set] : raster_->textureSets()) writeTextures(*layout, set);
  }
}

void Renderer::makeTextureInfos() {
  samplers_.clear();
  textureInfos_.clear();
  const std::vector<VkImageView> views = scene_.textureViews();
  const std::vector<SamplerDesc>& descs = scene_.textureSamplers();
  std::vector<SamplerDesc> made;
  for (size_t i = 0; i < views.size(); ++i) {
    const size_t k = std::find(made.begin(), made.end(), descs[i]) - made.begin();
    if (k == made.size()) made.push_back(descs[i]), samplers_.push_back(makeSampler(ctx_, samplerSettings_, descs[i]));
    textureInfos_.push_back({samplers_[k].get(), views[i], VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
  }
}

// The textures that are in (a view), or of those only the ones in `only`: runs of consecutive elements.
void Renderer::writeTextures(const vk::PipelineLayout& layout, VkDescriptorSet set, const std::vector<uint8_t>* only) const {
  if (!set) return;
  vk::DescriptorWriter w(ctx_, layout, 1, set);
  for (size_t i = 0; i < textureInfos_.size();) {
    auto wanted = [&](size_t k) { return textureInfos_[k].imageView && (!only || (*only)[k]); };
    if (!wanted(i)) {
      ++i;
      continue;
    }
    const size_t first = i;
    while (i < textureInfos_.size() && wanted(i)) ++i;
    w.images(0, {textureInfos_.begin() + first, textureInfos_.begin() + i}, uint32_t(first));
  }
  w.commit();
}

void Renderer::writeTextureSets(const std::vector<uint8_t>* only) {
  for (auto& set : pipelines_) {
    if (!set) continue;
    for (ScenePipelines& p : *set)
      if (p.pipeline && p.pipeline->layout.setCount() > 1)
        for (uint32_t frame = 0; frame < framesInFlight_; ++frame) writeTextures(p.pipeline->layout, p.sets.get(1, frame), only);
  }
  for (VisShade& v : shade_)
    if (v.pipeline && v.pipeline->layout.setCount() > 1) writeTextures(v.pipeline->layout, v.textures.get(1), only);
  if (raster_)
    for (const auto& [layout, set] : raster_->textureSets()) writeTextures(*layout, set, only);
  if (transparency_)
    for (const auto& [layout, set] : transparency_->textureSets()) writeTextures(*layout, set, only);
}

void Renderer::createTargets(VkExtent2D extent, bool visibility) {
  vkDeviceWaitIdle(ctx_.device());
  if (extent.width != extent_.width || extent.height != extent_.height) {
    color_ = {};  // made by the first frame that needs it
    depth_ = vk::Image(ctx_, {extent, kDepthFormat, 1, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, 0, 0, "scene depth"});
    vis_ = {};
    extent_ = extent;
    if (raster_) raster_->resize(extent);
  }
  if (visibility && !vis_.handle())
    vis_ = vk::Image(ctx_, {extent, kVisFormat, 1,
                            VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, 0,
                            0, "visibility"});
}

void Renderer::drawScene(VkCommandBuffer cb, uint32_t frame, PipelineSet set, const glm::vec3& eye) {
  KindPipelines& pipelines = *pipelines_[set];
  const bool vis = set == kVisibility;
  // This frame index's sets are not in use (its previous frame's fence signalled): point them at this
  // frame's uniforms, once each, before any is bound (kinds may share a pipeline).
  for (ScenePipelines& p : pipelines)
    if (p.pipeline && p.pipeline->layout.hasBinding(0, 0))
      vk::DescriptorWriter(ctx_, p.pipeline->layout, 0, p.sets.get(0, frame))
          .buffer(0, uniforms_.buffer, uniforms_.offset, sizeof(shader::FrameUniforms))
          .commit();
  for (size_t k = 0; k < kDrawKindCount; ++k) {  // the table's order is the draw order
    const DrawKind kind = DrawKind(k);
    const KindInfo& info = kKinds[k];
    ScenePipelines& p = pipelines[vis ? size_t(info.visAs) : k];
    if (!p.pipeline || !scene_.hasDraws(kind)) continue;
    const vk::Pipeline& pl = *p.pipeline;
    pl.bind(cb);
    for (uint32_t s = 0; s < pl.layout.setCount(); ++s) pl.bindSet(cb, s, p.sets.get(s, frame));
    // Streams by the vertex shader's input locations: the variant's reflected inputs are a prefix.
    const VkBuffer forward[3] = {scene_.positions(), scene_.normals(), scene_.texcoords()};
    const VkBuffer visStreams[2] = {scene_.positions(), scene_.texcoords()};
    const VkDeviceSize offsets[3] = {0, 0, 0};
    const uint32_t inputs = uint32_t(pl.layout.interface().stages[0].inputs.size());  // stage 0: the vertex stage
    vkCmdBindVertexBuffers(cb, 0, inputs, vis ? visStreams : forward, offsets);
    VkIndexType bound = VK_INDEX_TYPE_MAX_ENUM;
    for (const DrawItem* dp : nearestFirst(scene_.draws(kind), eye)) {
      const DrawItem& d = *dp;
      if (d.indexType != bound) {
        vkCmdBindIndexBuffer(cb, d.indexType == VK_INDEX_TYPE_UINT16 ? scene_.indices16() : scene_.indices32(), 0, d.indexType);
        bound = d.indexType;
      }
      if (!pl.layout.interface().pushConstants.empty()) pl.push(cb, shader::DrawPush{d.material, 0});  // vis: masked only
      vkCmdSetFrontFace(cb, d.mirrored ? VK_FRONT_FACE_CLOCKWISE : VK_FRONT_FACE_COUNTER_CLOCKWISE);
      vkCmdDrawIndexed(cb, d.indexCount, d.instanceCount, d.firstIndex, d.vertexOffset, d.firstInstance);
    }
  }
}

void Renderer::shadeVisibility(VkCommandBuffer cb, RasterPath raster, VkImageView display, bool clearIds) {
  const VisShade& shade = shade_[2 * size_t(raster) + (display != VK_NULL_HANDLE)];
  const vk::Pipeline& c = *shade.pipeline;
  c.bind(cb);
  // A scene may lack one index width: any storage buffer fills that binding (no draw reads it).
  const VkBuffer i16 = scene_.indices16() ? scene_.indices16() : scene_.indices32();
  const VkBuffer i32 = scene_.indices32() ? scene_.indices32() : scene_.indices16();
  vk::DescriptorWriter w(ctx_, c.layout, 0, VK_NULL_HANDLE);
  w.buffer(0, uniforms_.buffer, uniforms_.offset, sizeof(shader::FrameUniforms))
      .buffer(1, scene_.materials())
      .buffer(2, scene_.drawInfo())
      .buffer(3, scene_.positions())
      .buffer(4, scene_.normals())
      .buffer(5, i32)
      .buffer(6, i16)
      .buffer(10, scene_.instances())
      .buffer(15, scene_.visIdPages());
  if (display) w.image(16, display, VK_IMAGE_LAYOUT_GENERAL);
  else w.image(8, color_.view(), VK_IMAGE_LAYOUT_GENERAL);
  // glTF's streams, in the MATERIAL_EXTRAS variant only: any buffer where the scene has none (nothing reads it).
  if (c.layout.hasBinding(0, 13)) w.buffer(13, scene_.colors() ? scene_.colors() : scene_.positions());
  writeEnvironment(w, c.layout, env_.get());
  if (raster == RasterPath::Compute) w.buffer(14, raster_->ids());
  else w.image(7, vis_.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  if (c.layout.hasBinding(0, 9)) {  // the textured variant's
    w.buffer(9, scene_.texcoords());
    if (c.layout.hasBinding(0, 11)) w.buffer(11, scene_.texcoords1() ? scene_.texcoords1() : scene_.positions());
    if (c.layout.hasBinding(0, 12)) w.buffer(12, scene_.tangents() ? scene_.tangents() : scene_.positions());
  }
  w.push(cb, c);
  c.push(cb, shader::VisShadePush{scene_.visIdPageShift(), clearIds});
  if (c.layout.setCount() > 1) c.bindSet(cb, 1, shade.textures.get(1));
  c.dispatch(cb, extent_.width, extent_.height);  // one thread per pixel
}

void Renderer::frame(FrameContext& fc) {
  VkCommandBuffer cb = fc.frame.cb;
  const uint32_t frame = fc.frame.index;
  const CameraPose& pose = fc.pose;
  const Lens& lens = fc.lens;
  const RenderSettings& s = fc.settings;
  const RenderTarget& target = fc.target;
  // Every texture set is written again once no frame uses them for new samplers (samplers are cheap; a
  // user's change in the panel). Textures of a deferred load that came in since the last frame: only their
  // elements are written, which no pending frame uses (their materials' slots pointed at none until the
  // copy GpuScene submitted after those frames), so frames in flight go on; where the device does not
  // allow that, once they are done.
  if (s.sampler != samplerSettings_) {
    VK_CHECK(vkDeviceWaitIdle(ctx_.device()));
    samplerSettings_ = s.sampler;
    arrivalsSeen_ = scene_.textureArrivals();
    makeTextureInfos();
    writeTextureSets();
  } else if (scene_.textureArrivals() != arrivalsSeen_) {
    if (!ctx_.updateUnusedWhilePending()) VK_CHECK(vkDeviceWaitIdle(ctx_.device()));
    arrivalsSeen_ = scene_.textureArrivals();
    const std::vector<VkImageView> views = scene_.textureViews();
    std::vector<uint8_t> fresh(views.size(), 0);
    for (size_t i = 0; i < views.size(); ++i)
      if (views[i] && !textureInfos_[i].imageView) fresh[i] = 1, textureInfos_[i].imageView = views[i];
    writeTextureSets(&fresh);
  }
  const Plan plan = Renderer::plan(choice_, s, env_ != nullptr, fc.readSceneColor);
  const bool visibility = plan.visibility, display = plan.display, backdrop = plan.backdrop;
  const RasterPath raster = plan.raster;
  const bool compute = raster == RasterPath::Compute;
  const PipelineSet set = plan.set;
  if (target.extent.width != extent_.width || target.extent.height != extent_.height ||
      (raster == RasterPath::Hardware && !vis_.handle()))
    createTargets(target.extent, raster == RasterPath::Hardware);
  if (compute && !raster_) {
    raster_.emplace(ctx_, scene_, framesInFlight_, std::exchange(prepared_.raster, std::nullopt));
    raster_->resize(extent_);
    for (const auto& [layout, set] : raster_->textureSets()) writeTextures(*layout, set);
  }
  if (!compute) ensurePipelines(set);
  if (!display && !color_.handle())
    color_ = vk::Image(ctx_, {extent_, kColorFormat, 1,
                              VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                                  VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              0, 0, "scene colour"});
  VisShade& shade = shade_[2 * size_t(raster) + display];
  if (visibility && !shade.pipeline) shade = makeShade(compute, display);
  lastRaster_ = raster;
  const float aspect = float(target.extent.width) / float(target.extent.height);

  shader::FrameUniforms u{};
  u.view = viewMatrix(pose);
  u.viewProj = projectionMatrix(lens, aspect) * u.view;
  u.cameraPos = glm::vec4(pose.position, 1.0f);
  u.ambient = glm::vec4(s.lights.ambient, 0.0f);
  static_assert(MAX_LIGHTS == kMaxLights);
  u.lightCount.x = uint32_t(std::min(s.lights.lights.size(), kMaxLights));
  u.lightCount.y = s.sampler.filter != TextureFilter::Trilinear;  // the mip view shows whole levels
  for (uint32_t i = 0; i < u.lightCount.x; ++i) {
    const Light& l = s.lights.lights[i];
    const glm::vec3 p = l.kind == Light::Kind::Headlight ? pose.position : l.position;
    u.lights[i] =
        shader::makeGpuLight(unsigned(l.kind), p, l.color, l.falloff, l.direction, l.innerConeCos, l.outerConeCos, l.range);
  }
  u.params = glm::vec4(float(s.mode), s.lodBias, lens.zNear, lens.zFar);
  if (env_) {
    const EnvironmentMapSettings& es = env_->settings();
    u.environment =
        glm::vec4(float(es.specularLevels - 1), s.backdropBlur < 0.0f ? ENV_BACKDROP_COLOR : std::min(s.backdropBlur, 1.0f),
                  float(es.lutSize), env_->rotation());
  }
  u.background = glm::vec4(s.background, 0.0f);
  u.options.x = s.brdf ? uint32_t(*s.brdf) + 1u : 0u;
  {
    // Pixel rays from the inverse projection: h = M^-1 (ndc, 0.5, 1) is linear in the pixel, and
    // h.xyz - h.w cameraPos = h.w (point - cameraPos) points along the pixel's ray (scaled).
    const glm::dmat4 inv = glm::inverse(glm::dmat4(u.viewProj));
    const glm::dvec3 cam(pose.position);
    auto ray = [&](double x, double y) {
      const glm::dvec4 h = inv * glm::dvec4(2.0 * x / target.extent.width - 1.0, 2.0 * y / target.extent.height - 1.0, 0.5, 1.0);
      return glm::dvec3(h) - h.w * cam;
    };
    u.rayDir = glm::vec4(glm::vec3(ray(0, 0)), 0.0f);
    u.rayDx = glm::vec4(glm::vec3(ray(1, 0) - ray(0, 0)), 0.0f);
    u.rayDy = glm::vec4(glm::vec3(ray(0, 1) - ray(0, 0)), 0.0f);
  }
  // Through the frame's arena: a frame still in flight keeps its own uniforms (the ring flushes the arena).
  uniforms_ = fc.frame.upload(sizeof u, ctx_.properties().limits.minUniformBufferOffsetAlignment);
  std::memcpy(uniforms_.data, &u, sizeof u);

  if (env_) {  // left sampled by their build; a read-back (tests) may have moved them since
    constexpr VkPipelineStageFlags2 kShading = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
    vk::require(cb, {{env_->map().tracked(), vk::Use::Sampled, kShading},
                     {env_->source().tracked(), vk::Use::Sampled, kShading},
                     {env_->specular().tracked(), vk::Use::Sampled, kShading},
                     {env_->brdfLut().tracked(), vk::Use::Sampled, kShading}});
  }
  vk::GpuTimer& timer = timers_[frame];
  timer.reset(cb);
  timer.begin(cb);
  if (compute) {
    const float pixelsPerUnit = float(target.extent.height) / (2.0f * std::tan(glm::radians(lens.fovYDeg) * 0.5f));
    const CullCamera cam{u.viewProj, pose.position, lens.orthographic, s.lodError, pixelsPerUnit, lens.zNear};
    raster_->record(cb, uniforms_, timer, frame, cam, s.cull, s.clip, s.counters);
    vk::bufferBarrier(cb, vk::kComputeWrite | vk::kFragmentWrite, vk::kComputeRead);
  } else {
    rasterPass(cb, frame, set, pose.position, s.background, backdrop);
    timer.mark(cb, visibility ? "visibility" : "scene");
    if (backdrop) {
      backdropPass(cb);
      timer.mark(cb, "backdrop");
    }
  }
  const bool transparent = !display && transparency_ && s.mode == VIEW_SHADED;  // debug views show the opaque surfaces only
  // The shading pass is the compute ids' last reader unless the transparency pass or a read-back comes after
  // it: then it clears them behind it and the next frame's rasteriser skips its clear (ComputeRaster::foldClear).
  const bool clearIds = compute && raster_->foldClear() && !transparent && !s.keepIds;
  if (visibility) {
    const vk::Requirement out{display ? target.image : color_.tracked(), vk::Use::Storage, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                              true};
    if (compute) vk::require(cb, {out});
    else vk::require(cb, {{vis_.tracked(), vk::Use::Sampled, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT}, out});
    shadeVisibility(cb, raster, display ? target.view : VK_NULL_HANDLE, clearIds);
    if (clearIds) raster_->shadingCleared();
    timer.mark(cb, "shade");
  }
  if (display) return;
  if (transparent) {
    transparency_->record(cb, uniforms_, color_, depth_, extent_, pose.position, compute ? raster_->ids() : VK_NULL_HANDLE);
    timer.mark(cb, "transparent");
  }
  post_.record(cb, color_.tracked(), color_.view(), target.image, target.view, target.format, target.extent, s.mosaic);
  timer.mark(cb, "post");
}

// The scene pass by the hardware: forward colour or visibility ids, with depth.
void Renderer::rasterPass(VkCommandBuffer cb, uint32_t frame, PipelineSet set, const glm::vec3& eye, const glm::vec3& background,
                          bool backdrop) {
  const bool visibility = set == kVisibility;
  // Old contents are discarded; the tracker waits for the previous frame's readers (post or shading pass).
  const vk::Image& target0 = visibility ? vis_ : color_;
  vk::require(cb, {{target0.tracked(), vk::Use::ColorAttachment, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, true},
                   {depth_.tracked(), vk::Use::DepthAttachment,
                    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT, true}});
  VkRenderingAttachmentInfo colorAtt{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  colorAtt.imageView = target0.view();
  colorAtt.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  colorAtt.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  colorAtt.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  if (visibility) colorAtt.clearValue.color.uint32[0] = VIS_EMPTY;
  else colorAtt.clearValue.color = {{background.r, background.g, background.b, backdrop ? 0.0f : 1.0f}};  // 0: backdropPass's
  VkRenderingAttachmentInfo depthAtt{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  depthAtt.imageView = depth_.view();
  depthAtt.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
  depthAtt.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  depthAtt.storeOp = transparency_ ? VK_ATTACHMENT_STORE_OP_STORE : VK_ATTACHMENT_STORE_OP_DONT_CARE;  // it tests
  depthAtt.clearValue.depthStencil = {1.0f, 0};
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.renderArea = {{0, 0}, extent_};
  ri.layerCount = 1;
  ri.colorAttachmentCount = 1;
  ri.pColorAttachments = &colorAtt;
  ri.pDepthAttachment = &depthAtt;
  vkCmdBeginRendering(cb, &ri);
  vk::setFullViewport(cb, extent_);
  drawScene(cb, frame, set, eye);
  vkCmdEndRendering(cb);
}

}  // namespace rtr::render

namespace rtr::render {

uint32_t Renderer::copyIds(VkCommandBuffer cb, VkBuffer dst) {
  if (lastRaster_ == RasterPath::Compute) {
    if (idsCleared()) throw Error("copyIds: the last frame's shading pass cleared its ids (RenderSettings::keepIds)");
    vk::bufferBarrier(cb, vk::kComputeWrite | vk::kFragmentWrite, vk::kCopyRead);
    const VkBufferCopy region{0, 0, VkDeviceSize(extent_.width) * extent_.height * 8};
    vkCmdCopyBuffer(cb, raster_->ids(), dst, 1, &region);
    vk::bufferBarrier(cb, vk::kCopyWrite, vk::kHostRead);
    return 8;
  }
  if (lastRaster_ != RasterPath::Hardware) throw Error("copyIds: the last frame made no visibility ids");
  vk::require(cb, vis_.tracked(), vk::Use::CopySrc, VK_PIPELINE_STAGE_2_COPY_BIT);
  vk::copyImageToHost(cb, vis_.handle(), extent_, dst);
  return 4;
}

}  // namespace rtr::render
