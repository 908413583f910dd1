#pragma once
// One frame of the renderer, start to end: the scene pass (shaded or a debug view) into an intermediate
// linear-light image, then the post pass (mosaic or copy) into the target (a swapchain image or an
// offscreen image). Knows no window.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.hpp"
#include "frame.h"
#include "render/gpu_scene.hpp"
#include "render/post.hpp"
#include "vk/commands.hpp"
#include "vk/pipeline.hpp"

namespace rtr::render {

struct RenderSettings {
  int mode = VIEW_SHADED;         // VIEW_* from frame.h
  float lodBias = 0.0f;
  MosaicMode mosaic = MosaicMode::Compute;
  glm::vec3 lightPos{-0.2972f, 7.3100f, -11.9532f};  // the brief's standard light
  glm::vec3 lightColor{1.0f};
  bool inverseSquareFalloff = false;
  glm::vec3 ambient{0.02f};
};

struct RenderTarget {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;  // a UNORM format: the post pass encodes sRGB itself
  VkExtent2D extent{};
  VkImageLayout finalLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
};

class Renderer {
 public:
  static constexpr VkFormat kColorFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
  static constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

  Renderer(const vk::Context& ctx, const GpuScene& scene, uint32_t framesInFlight);

  // Records the whole frame; `frame` picks the per-frame-in-flight uniform buffer and timer.
  void record(VkCommandBuffer cb, uint32_t frame, const CameraPose& pose, const Lens& lens,
              const RenderSettings& settings, const RenderTarget& target);
  // Per-pass GPU times of the last completed use of `frame`, in ms.
  std::vector<std::pair<std::string, double>> gpuTimes(uint32_t frame) const { return timers_[frame].results(); }
  // The linear-light intermediate image of the last frame (SHADER_READ_ONLY_OPTIMAL after a frame).
  const vk::Image& sceneColor() const { return color_; }
  // Rebuilds the scene pipelines from the shader folder (hot reload); on error keeps the old ones.
  void rebuildPipelines();

 private:
  struct ScenePipelines {
    std::optional<vk::Pipeline> pipeline;
    vk::DescriptorSets sets;
  };
  void createTargets(VkExtent2D extent);
  ScenePipelines makePipeline(DrawKind kind, bool debug) const;
  void drawScene(VkCommandBuffer cb, uint32_t frame, bool debug);

  const vk::Context& ctx_;
  const GpuScene& scene_;
  uint32_t framesInFlight_;
  std::vector<vk::Buffer> uniforms_;  // FrameUniforms, one per frame in flight
  std::array<ScenePipelines, kDrawKindCount> shaded_, debug_;
  MosaicPass post_;
  std::vector<vk::GpuTimer> timers_;
  vk::Image color_, depth_;
  VkExtent2D extent_{0, 0};
};

}  // namespace rtr::render
