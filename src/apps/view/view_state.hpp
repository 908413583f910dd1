#pragma once
// What the windowed viewer's keys, mouse, panel and drops change; read by its render loop.
#include <deque>
#include <map>
#include <string>
#include <vector>

#include "camera_controller.hpp"
#include "render/mips.hpp"
#include "render/renderer.hpp"
#include "trace/tracer.hpp"

namespace rtr::view {

struct ViewState {
  CameraController camera{{}, {}};
  CameraPose startPose;            // Home returns here
  Lens lens;                       // fov from the panel
  render::RenderSettings settings;
  render::MipMode mips = render::MipMode::Compute;
  bool panel = true, resized = false;
  // One-shot requests, served by the render loop.
  bool traceRequested = false, errorMapRequested = false, reframeRequested = false, homeRequested = false;
  bool screenshotRequested = false, remipRequested = false;
  std::vector<std::string> drops;  // files dropped on the window (the last one is loaded)
  // Ray tracer (docs/formats.md's toggles, on keys that do not clash with the view modes).
  trace::Shading traceShading = trace::Shading::Phong;
  bool traceShadows = true, traceReflections = true, traceOrtho = false;
  std::string message;             // the last load / screenshot outcome, shown in the panel
  bool messageIsError = false;
};

// What the panel shows but does not change.
struct PanelFacts {
  std::string scenePath;
  uint32_t meshes = 0, materials = 0, textures = 0, triangles = 0;
  double mipGpuMs = 0;
  std::string traceStatus, shaderError;
  float maxAnisotropy = 1;  // the device's; 1: no anisotropic filtering
  size_t texturesDecoded = 0;     // of `textures`
  bool texturesLoading = false;   // not all in yet: materials show their factors
  const std::vector<std::pair<std::string, double>>* startup = nullptr;  // phases in ms; empty before the first frame
  double startupTotalMs = 0, texturesInAtMs = 0;                         // from process start; 0: not yet
};

// The last kFrames frames' CPU time and per-pass GPU times, for the panel's graphs.
struct FrameHistory {
  static constexpr size_t kFrames = 300;
  std::deque<float> cpuMs;
  std::map<std::string, std::deque<float>> gpuMs;  // by pass name
  void add(float cpu, const std::vector<std::pair<std::string, double>>& gpu);
};

const char* modeName(int mode);  // "shaded", "mip level", ... (1..VIEW_COUNT)

// The settings panel (Dear ImGui): one window, between ImGui::NewFrame and ImGui::Render.
void drawPanel(ViewState& s, const PanelFacts& facts, const FrameHistory& history);

}  // namespace rtr::view
