#pragma once
// One frame of the renderer, start to end: the scene pass (shaded or a debug view) into an intermediate
// linear-light image, then the post pass (mosaic or copy) into the target (a swapchain image or an
// offscreen image); where nothing else needs the intermediate image (visibility path, mosaic off, no
// transparent surfaces) the shading pass writes the target itself. Knows no window.
#include <array>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/enum_names.hpp"
#include "core/camera.hpp"
#include "frame.h"
#include "render/environment_maps.hpp"
#include "render/gpu_scene.hpp"
#include "render/post.hpp"
#include "render/raster.hpp"
#include "render/transparency.hpp"
#include "scene/lights.hpp"
#include "vk/commands.hpp"
#include "vk/frame_ring.hpp"
#include "vk/pipeline.hpp"

namespace rtr::render {

// How the shaded view (mode 1) is made: forward (BRDF in the scene pass's fragment shaders) or a
// visibility buffer (triangle ids rasterised, BRDF in a compute pass; docs/design.md). Debug views
// are always forward.
enum class ShadingPath { Forward, Visibility };
constexpr std::array<EnumName<ShadingPath>, 2> enumNames(ShadingPath) {
  return {{{ShadingPath::Visibility, "visibility"}, {ShadingPath::Forward, "forward"}}};
}

// Who rasterises the visibility buffer: the hardware (an R32 id image, depth-tested) or the compute
// rasteriser (render/raster.hpp, a 64-bit buffer); Auto: the device's default (defaultRaster).
enum class RasterPath { Auto, Hardware, Compute };
constexpr std::array<EnumName<RasterPath>, 3> enumNames(RasterPath) {
  return {{{RasterPath::Auto, "auto"}, {RasterPath::Hardware, "hardware"}, {RasterPath::Compute, "compute"}}};
}

struct RenderSettings {
  int mode = VIEW_SHADED;                         // VIEW_* from frame.h
  ShadingPath shading = ShadingPath::Visibility;  // fastest measured (docs/bench/gpu-passes.md)
  RasterPath raster = RasterPath::Auto;
  // Auto: one pass of frustum and cones where a level-of-detail cut is drawn, none otherwise; measured on
  // the H200, a culling pass costs more than it saves in the default scene and two phases more than one
  // with a cut (docs/culling.md).
  Culling cull = Culling::Auto;
  // Compute raster: the triangles crossing the near plane (w = 0) or the guard band clipped in compute (a
  // small pass, docs/raster.md) rather than drawn by the hardware. Off by default: on the H100 the pass
  // took 0.48 ms for the default temple's 16 walls, the hardware 0.12 ms (docs/raster.md).
  bool clip = false;
  // Compute raster, scenes with a cluster hierarchy: the level-of-detail cut's projected error in pixels
  // (docs/virtual-geometry.md); 0: full detail, exactly the image without a hierarchy.
  float lodError = 0.0f;  // rtr-view: --lod-error, default 0 (full detail)
  // Compute raster: the frame's counters (hand-off, clipped and medium triangles, culling) read back for
  // cullStats() and the like: small copies between the passes (9 µs a frame on the H200). rtr-view --bench
  // times its frames without them and reads them in one frame after.
  bool counters = true;
  // Compute raster: the frame's ids are left in the visibility buffer for a read-back after it (copyIds;
  // HeadlessRenderer::ids sets it). Otherwise, where no transparency pass reads them either, the shading pass
  // clears them behind it, so that the next frame skips the clear (ComputeRaster::foldClear, docs/raster.md).
  bool keepIds = false;
  float lodBias = 0.0f;
  SamplerSettings sampler;  // how scene textures are filtered (mip experiments)
  MosaicMode mosaic = MosaicMode::Compute;
  // The shaded view's lights (at most MAX_LIGHTS; a headlight follows the camera) and ambient colour;
  // the apps resolve them once from the scene and the command line (scene/lights.hpp).
  LightRig lights{{briefLight()}, glm::vec3(0.02f), {}};
  // What pixels nothing covers show: the environment (Renderer::setEnvironment) at this blur (0: sharp;
  // (0, 1]: the specular cube at that roughness; < 0: not at all), else `background` (linear). The
  // library's default is black, the image of every release before environments; rtr-view's is grey.
  glm::vec3 background{0.0f};
  float backdropBlur = 0.0f;
  std::optional<int> brdf;  // BRDF_BECKMANN or BRDF_GGX (brdf.h) for every material; none: each material's
};

// The frame leaves the target written by the post pass or the shading pass (its state tracked); the caller
// requires what comes next (a copy, presentation).
struct RenderTarget {
  vk::TrackedImage image;
  VkImageView view = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;  // a UNORM format: the post pass encodes sRGB itself
  VkExtent2D extent{};
};

// What one frame needs: the frame in flight (its command buffer, still recording, and its index), the view,
// and where the picture goes. The window app and the headless target both fill one per frame.
struct FrameContext {
  vk::Frame& frame;
  CameraPose pose;
  Lens lens;
  RenderSettings settings;
  RenderTarget target;
  bool readSceneColor = false;  // the caller reads sceneColor() after the frame: it is written even where not needed
};

// The draws nearest `eye` first (by their meshes' box centres; ties keep their order): drawn so, the depth
// test rejects hidden fragments before they are shaded (measured: a shorter forward pass on lavapipe;
// only fragments at equal depth could come out differently).
std::vector<const DrawItem*> nearestFirst(std::span<const DrawItem> draws, const glm::vec3& eye);

class Renderer {
  enum PipelineSet { kShaded, kDebug, kVisibility, kPipelineSetCount };  // built on first use

 public:
  static constexpr VkFormat kColorFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
  static constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
  static constexpr VkFormat kVisFormat = VK_FORMAT_R32_UINT;  // draw index, primitive index (frame.h)

  // The pipelines a first frame uses, made from the scene's kinds alone: creation only (reflection,
  // layouts, the driver), no buffer and no descriptor, so that they can be made on another thread while
  // the scene uploads (render/startup.hpp's PipelinesAhead; docs/startup.md "Phases side by side").
  struct Prepared {
    SceneKinds kinds;
    bool environment = false;
    std::array<std::optional<vk::Pipeline>, kPipelineSetCount * kDrawKindCount> scene;  // by set, then draw kind
    std::array<std::optional<vk::Pipeline>, 6> shade;                                   // as shade_
    std::optional<ComputeRaster::Pipelines> raster;
    std::optional<vk::Pipeline> mosaic, backdrop;
  };
  // Makes, in parallel, those that a frame with `first` will use (one whose scene colour is not read back)
  // for a scene of these kinds, with an environment or none (setEnvironment). Any thread.
  static Prepared prepare(const vk::Context& ctx, const SceneKinds& kinds, const RenderSettings& first, bool environment);

  // `prepared`: taken on their first use where made for this scene's kinds and environment; the rest is
  // made on first use.
  Renderer(const vk::Context& ctx, const GpuScene& scene, uint32_t framesInFlight, Prepared prepared);
  Renderer(const vk::Context& ctx, const GpuScene& scene, uint32_t framesInFlight);

  // Light from an environment, added to the lights by the shaded view of both paths, and the backdrop;
  // null: none (no environment pipeline, descriptor or texture). Waits for the device; the shaded
  // pipelines are made again on their next use.
  void setEnvironment(std::shared_ptr<const EnvironmentMaps> env);
  const EnvironmentMaps* environment() const { return env_.get(); }

  // Records the whole frame into fc.frame's command buffer; its index picks the uniforms and timer.
  void frame(FrameContext& fc);
  // Per-pass GPU times of the last completed use of `frame`, in ms.
  std::vector<std::pair<std::string, double>> gpuTimes(uint32_t frame) const { return timers_[frame].results(); }
  // The linear-light intermediate image of the last frame that wrote it (FrameContext::readSceneColor; its
  // state tracked: require() before use).
  const vk::Image& sceneColor() const { return color_; }
  // Rebuilds the scene pipelines from the shader folder (hot reload); on error keeps the old ones.
  void rebuildPipelines();
  // The path a frame with these settings takes: Visibility needs the geometryShader feature
  // (gl_PrimitiveID), a shaded view and ids that fit 32 bits; otherwise Forward.
  ShadingPath pathFor(const RenderSettings& settings) const;
  // Who rasterises the visibility buffer for these settings (Hardware or Compute; Auto resolved): the one
  // asked for where the device can, else the other.
  RasterPath rasterFor(const RenderSettings& settings) const;
  // Records a copy of the last frame's visibility ids into `dst` (host-visible, 8 bytes a pixel at most);
  // returns the bytes per pixel written: 4 (hardware: the id) or 8 (compute: id in the low half). The compute
  // ids only of a frame with RenderSettings::keepIds (or a transparency pass): an Error otherwise.
  uint32_t copyIds(VkCommandBuffer cb, VkBuffer dst);
  // Whether the last frame's shading pass cleared the compute rasteriser's ids behind it (RenderSettings::keepIds).
  bool idsCleared() const { return lastRaster_ == RasterPath::Compute && raster_->idsCleared(); }
  // Why the scene cannot take the visibility path on this device (frames are forward); empty if it can.
  const std::string& visibilityRefusal() const { return choice_.visibilityRefusal; }
  // The culling counts of the last completed use of `frame`; none where it did not cull.
  // (None either, here and below, where that frame's counters were not read: RenderSettings::counters.)
  std::optional<ComputeRaster::CullStats> cullStats(uint32_t frame) const {
    return counted(frame) ? raster_->cullStats(frame) : std::nullopt;
  }
  // Triangles the compute rasteriser handed to the hardware in the last completed use of `frame`.
  std::optional<uint32_t> handOffTriangles(uint32_t frame) const {
    return counted(frame) ? std::optional(raster_->handOffTriangles(frame)) : std::nullopt;
  }
  uint32_t handOffCapacity() const { return raster_ ? raster_->handOffCapacity() : 0; }
  // Triangles the compute rasteriser clipped itself in the last completed use of `frame`.
  std::optional<uint32_t> clippedTriangles(uint32_t frame) const {
    return counted(frame) ? std::optional(raster_->clippedTriangles(frame)) : std::nullopt;
  }
  // Medium triangles the compute rasteriser found in the last completed use of `frame` (ComputeRaster).
  std::optional<ComputeRaster::MediumCounts> mediumTriangles(uint32_t frame) const {
    return counted(frame) ? std::optional(raster_->mediumTriangles(frame)) : std::nullopt;
  }

 private:
  bool counted(uint32_t frame) const { return raster_ && raster_->counted(frame); }
  struct ScenePipelines {
    std::optional<vk::Pipeline> pipeline;
    vk::DescriptorSets sets;
  };
  using KindPipelines = std::array<ScenePipelines, kDrawKindCount>;
  struct VisShade {
    std::optional<vk::Pipeline> pipeline;
    vk::DescriptorSets textures;  // set 1; set 0 is pushed per frame
  };
  // What picks a frame's path and pipelines: the device's features and the scene's kinds (no buffers), so
  // that prepare() picks what frame() will.
  struct Choice {
    Choice(const vk::Context& ctx, const SceneKinds& kinds);
    ShadingPath pathFor(const RenderSettings& s) const;
    RasterPath rasterFor(const RenderSettings& s) const;
    SceneKinds kinds;
    bool canUseVisibility = false, canHardware = false, canCompute = false, cpuDevice = false;
    std::string visibilityRefusal;
  };
  // What a frame records: its path, whose ids, which scene pipelines; display: the shading pass writes the
  // target; backdrop: the forward shaded view's environment pass.
  struct Plan {
    bool visibility;
    RasterPath raster;
    PipelineSet set;
    bool display, backdrop;
  };
  static Plan plan(const Choice& c, const RenderSettings& s, bool environment, bool readSceneColor);
  // The pipelines of the draw kinds that `set` draws for a scene of these kinds, by kind.
  static std::array<bool, kDrawKindCount> kindsOf(const SceneKinds& kinds, PipelineSet set);
  static vk::Pipeline makeScenePipeline(const vk::Context& ctx, const SceneKinds& kinds, PipelineSet set, size_t kind,
                                        bool environment);
  static vk::Pipeline makeShadePipeline(const vk::Context& ctx, const SceneKinds& kinds, bool fromBuffer, bool display,
                                        bool environment);
  static vk::Pipeline makeBackdrop(const vk::Context& ctx);
  // A prepared pipeline, once, where made for this environment; else none.
  std::optional<vk::Pipeline> takePrepared(std::optional<vk::Pipeline>& slot, bool dependsOnEnvironment);
  void createTargets(VkExtent2D extent, bool visibility);
  ScenePipelines withSets(vk::Pipeline pipeline) const;  // its descriptor sets, written
  KindPipelines makePipelines(PipelineSet set);
  VisShade makeShade(bool fromBuffer, bool display);
  void backdropPass(VkCommandBuffer cb);
  void ensurePipelines(PipelineSet set);
  void rasterPass(VkCommandBuffer cb, uint32_t frame, PipelineSet set, const glm::vec3& eye, const glm::vec3& background,
                  bool backdrop);
  void drawScene(VkCommandBuffer cb, uint32_t frame, PipelineSet set, const glm::vec3& eye);
  // display: the target's view, written sRGB-encoded (no post pass); null: the linear image. clearIds: the
  // compute rasteriser's ids cleared behind it (VisShadePush::clearIds).
  void shadeVisibility(VkCommandBuffer cb, RasterPath raster, VkImageView display, bool clearIds);
  // The scene's texture array, as every pipeline that samples it binds it (set 1, binding 0): each
  // texture with a sampler made from its own SamplerDesc and the settings (one per distinct pair).
  void makeTextureInfos();
  // The one writer: every texture that is in, or those of them marked in `only`.
  void writeTextures(const vk::PipelineLayout& layout, VkDescriptorSet set, const std::vector<uint8_t>* only = nullptr) const;
  void writeTextureSets(const std::vector<uint8_t>* only = nullptr);  // of every pipeline built

  const vk::Context& ctx_;
  const GpuScene& scene_;
  uint32_t framesInFlight_;
  SamplerSettings samplerSettings_;
  std::vector<vk::Sampler> samplers_;  // made from samplerSettings_, one per distinct SamplerDesc
  std::vector<VkDescriptorImageInfo> textureInfos_;
  uint64_t arrivalsSeen_;            // the scene's textureArrivals() when the texture sets were last written
  vk::UploadArena::Slice uniforms_;  // this frame's FrameUniforms, in its upload arena
  std::array<std::optional<KindPipelines>, kPipelineSetCount> pipelines_;
  // By 2 * RasterPath + display: Hardware reads the id image, Compute the 64-bit buffer; display writes the target.
  std::array<VisShade, 6> shade_;
  std::optional<ComputeRaster> raster_;  // built on first use
  std::shared_ptr<const EnvironmentMaps> env_;
  std::optional<vk::Pipeline> backdrop_;          // the forward path's environment backdrop, on first use
  std::optional<TransparencyPass> transparency_;  // a scene with blended draws only
  RasterPath lastRaster_ = RasterPath::Auto;
  Choice choice_;
  Prepared prepared_;  // what is left of them
  MosaicPass post_;
  std::vector<vk::GpuTimer> timers_;
  vk::Image color_, depth_, vis_;  // color_ only once a frame needed it, vis_ once the hardware visibility path ran
  VkExtent2D extent_{0, 0};
};

}  // namespace rtr::render
