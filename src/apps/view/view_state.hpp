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
  CameraPose startPose;  // Home returns here
  Lens lens;             // fov from the panel
  render::RenderSettings settings;
  render::MipMode mips = render::MipMode::Compute;
  bool panel = true, resized = false;
  // One-shot requests, served by the render loop.
  bool traceRequested = false, errorMapRequested = false, reframeRequested = false, homeRequested = false;
  bool screenshotRequested = false, remipRequested = false;
  std::vector<std::string> drops;  // files dropped on the window (the last one is loaded)
  int fileStep = 0;                // Left/Right: the previous/next file of the command line or folder
  bool reloadRequested = false;    // F5: the scene file read again
  // Ray tracer (the course framework's toggles, docs/formats.md, on keys that do not clash with the view modes).
  trace::Shading traceShading = trace::Shading::Phong;
  bool traceShadows = true, traceReflections = true, traceOrtho = false;
  // The environment's controls (the panel; the backdrop's blur is settings.backdropBlur): the render loop
  // prefilters the environment again (Renderer::setEnvironment) when a slider is let go (envChanged).
  bool hasEnvironment = false, envChanged = false;
  float envIntensity = 1.0f, envRotationDeg = 0.0f;
  std::string message;  // the last load / screenshot outcome, shown in the panel
  bool messageIsError = false;
};

// What the panel shows but does not change.
struct PanelFacts {
  std::string scenePath;
  uint32_t meshes = 0, materials = 0, textures = 0, triangles = 0;
  double mipGpuMs = 0;
  std::string traceStatus, shaderError;
  float maxAnisotropy = 1;                                               // the device's; 1: no anisotropic filtering
  size_t texturesDecoded = 0, texturesIn = 0;                            // of `textures`: decoded, on screen
  bool texturesLoading = false;                                          // not all in yet: materials show their factors
  const std::vector<std::pair<std::string, double>>* startup = nullptr;  // phases in ms; empty before the first frame
  double startupTotalMs = 0, texturesInAtMs = 0;                         // from process start; 0: not yet
  float depthFar = 0;                                                    // the linear depth view's white (its far plane)
  bool errorMap = false;                                                 // the error map is on screen: its scale is shown
};

// The last kFrames frames' CPU time and per-pass GPU times, for the panel's graphs.
struct FrameHistory {
  static constexpr size_t kFrames = 300;
  std::deque<float> cpuMs;
  std::map<std::string, std::deque<float>> gpuMs;  // by pass name
  void add(float cpu, const std::vector<std::pair<std::string, double>>& gpu);
};

const char* modeName(int mode);  // "shaded", "mip level", ... (1..VIEW_COUNT)

// The settings panel (Dear ImGui): one window, between ImGui::NewFrame and ImGui::Render. It starts
// collapsed to its title bar (a click opens it); its "Keys" section lists every key.
void drawPanel(ViewState& s, const PanelFacts& facts, const FrameHistory& history);
// The legend of what is on screen (between NewFrame and Render, shown with or without the panel): the mip
// level colours, the linear depth range, the error map's scale.
void drawLegend(const ViewState& s, const PanelFacts& facts);
// Every key of the window, as "key", "what it does" pairs (the panel's Keys section; rtr-view --help says the same).
const std::vector<std::pair<const char*, const char*>>& keyList();
// Test-only: each widget's rectangle (framebuffer pixels) on stdout when it changes, "ui ID x0 y0 x1 y1",
// so the window test can click and drag the panel with xdotool.
void setPanelTracking(bool on);
bool panelTracking();

// The window title: mode, settings, timings, the tracer's status and a shader error (the window test reads it).
std::string windowTitle(const ViewState& s, const std::vector<std::pair<std::string, double>>& gpuTimes,
                        const std::string& traceStatus, const std::string& shaderError, double cpuFrameMs);

}  // namespace rtr::view
