#pragma once
// Offscreen rendering with no window and no display: the frame goes to an image that is read back.
#include <functional>
#include <string>
#include <vector>

#include "core/image.hpp"
#include "render/renderer.hpp"

namespace rtr::render {

struct HeadlessFrame {
  ImageRGBA8 image;                                      // the post-processed target, as a viewer would show it (sRGB-encoded)
  ImageF sceneColor;                                     // the linear-light intermediate image (filled when asked for)
  std::vector<std::pair<std::string, double>> gpuTimes;  // ms per pass, of the last frame
};

class HeadlessRenderer {
 public:
  HeadlessRenderer(const vk::Context& ctx, const GpuScene& scene, VkExtent2D extent, Renderer::Prepared prepared = {});

  // Renders `frames` frames (the last one is read back).
  HeadlessFrame render(const CameraPose& pose, const Lens& lens, const RenderSettings& settings, int frames = 1,
                       bool readSceneColor = false);
  // Renders one frame and returns its visibility ids, row by row (VIS_EMPTY where nothing was drawn); the
  // frame keeps them (RenderSettings::keepIds).
  std::vector<uint32_t> ids(const CameraPose& pose, const Lens& lens, const RenderSettings& settings);
  // The target made again at `extent` (the next frame's renderer resizes its buffers, as a window's would).
  void resize(VkExtent2D extent);
  const Renderer& renderer() const { return renderer_; }
  Renderer& renderer() { return renderer_; }
  // Renders `frames` frames, one submission each, and returns every frame's per-pass GPU times.
  std::vector<std::vector<std::pair<std::string, double>>> bench(const CameraPose& pose, const Lens& lens,
                                                                 const RenderSettings& settings, int frames);

 private:
  RenderTarget target() const { return {target_.tracked(), target_.view(), target_.format(), extent_}; }
  // One frame through Renderer::frame, as the window app's; `after` records more into it. Waits for it.
  void frame(const CameraPose& pose, const Lens& lens, const RenderSettings& settings,
             const std::function<void(VkCommandBuffer)>& after = {}, bool readSceneColor = false);

  const vk::Context& ctx_;
  VkExtent2D extent_;
  Renderer renderer_;
  vk::FrameRing ring_;  // one frame: each is waited for (a read-back, a timing)
  vk::Image target_;
  vk::Buffer readback_, colorReadback_, idReadback_;
};

}  // namespace rtr::render
