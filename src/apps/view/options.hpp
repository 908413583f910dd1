#pragma once
// Command-line options of rtr-view, shared by the headless and the windowed paths.
#include <optional>
#include <string>

#include "core/camera.hpp"
#include "render/mips.hpp"
#include "render/renderer.hpp"

namespace rtr::view {

struct ViewOptions {
  std::string scene;
  bool headless = false;
  uint32_t width = 1280, height = 720;
  std::optional<CameraPose> camera;
  Lens lens;
  render::RenderSettings settings;
  render::MipMode mips = render::MipMode::Compute;
  int frames = 1;                  // frames to render before the screenshot
  std::string screenshot;          // image path (.png, .jpg, .exr, .hdr); empty: none
  bool force = false;              // overwrite an existing screenshot
  int bench = 0;                   // frames to time after warm-up; 0: no benchmark
  bool watch = false;              // hot-reload shaders
  std::string device;
  bool validation = false;
};

// The start pose: --camera, else the scene's own view, else a view down -z framing the bounds.
CameraPose startPose(const ViewOptions& o, const std::optional<CameraPose>& sceneView, const Bounds& bounds);

int runHeadless(const ViewOptions& o);
int runWindowed(const ViewOptions& o);

}  // namespace rtr::view
