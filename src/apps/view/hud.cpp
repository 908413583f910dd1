// What the window shows besides the panel: its title, the key list and the legend of the view on screen.
#include <cstdio>

#include <imgui.h>

#include "frame.h"
#include "view_state.hpp"

namespace rtr::view {

std::string windowTitle(const ViewState& s, const std::vector<std::pair<std::string, double>>& gpuTimes,
                        const std::string& traceStatus, const std::string& shaderError, double cpuFrameMs) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "rtr-view | mode %d | %s | mosaic %s | lod bias %.2f | %s x%g | %s | CPU frame %.2f ms",
                s.settings.mode, modeName(s.settings.mode), enumName(s.settings.mosaic), s.settings.lodBias,
                enumName(s.settings.sampler.filter), s.settings.sampler.anisotropy,
                s.camera.mode() == CameraMode::Orbit ? "orbit" : "fly", cpuFrameMs);
  std::string title = buf;
  for (const auto& [name, ms] : gpuTimes) {
    std::snprintf(buf, sizeof buf, " | %s %.3f ms", name.c_str(), ms);
    title += buf;
  }
  if (!traceStatus.empty()) title += " | " + traceStatus.substr(0, traceStatus.find('\n'));
  if (!shaderError.empty()) title += " | SHADER ERROR: " + shaderError.substr(0, shaderError.find('\n'));
  return title;
}

const std::vector<std::pair<const char*, const char*>>& keyList() {
  // The labels are those of docs/viewer.md's key table (tests/first_minute/docs_test.py compares them).
  static const std::vector<std::pair<const char*, const char*>> keys{
      {"W / S", "move forward / back"},
      {"A / D", "move left / right"},
      {"E / Q", "move up / down"},
      {"Shift, Ctrl (held)", "move faster (x5), slower (x0.05)"},
      {"right mouse button", "mouse-look on/off (fly mode)"},
      {"left / middle drag, scroll", "orbit mode: turn about the target, pan, zoom"},
      {"1-7", "views: 1 shaded, 2 mip level, 3 linear depth, 4 depth derivatives, 5 normal, 6 view dir, 7 light dir"},
      {"8 / 9 / 0", "views 8-10: BRDF terms D, F, G"},
      {"- / =", "views 11-12: diffuse, specular term"},
      {"M", "mosaic post-process off / compute / graphics"},
      {"[ / ]", "LOD bias -/+ 0.5"},
      {"F", "frame the scene"},
      {"Home", "back to the start pose"},
      {"C", "print the camera pose (--camera)"},
      {"Left / Right", "previous / next file of the command line or folder"},
      {"F5", "read the scene file again"},
      {"R", "ray-trace this view on the CPU (again: hide)"},
      {"T / Y / U / O", "CPU trace: shading phong/pbr/normals, shadows, reflections, orthographic"},
      {"X", "error map: this frame against a CPU trace (again: hide)"},
      {"F1 or H", "settings panel and legend on / off"},
      {"Esc", "quit"}};
  return keys;
}

void drawLegend(const ViewState& s, const PanelFacts& facts) {
  const int mode = s.settings.mode;
  if (!facts.errorMap && mode != VIEW_MIP_LEVEL && mode != VIEW_LINEAR_DEPTH) return;
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  ImGui::SetNextWindowPos(ImVec2(8, display.y - 8), ImGuiCond_Always, ImVec2(0, 1));
  ImGui::SetNextWindowBgAlpha(0.6f);
  ImGui::Begin("legend", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoFocusOnAppearing |
                   ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoInputs);
  auto swatch = [](ImVec4 c, const char* label) {
    ImGui::ColorButton(label, c, ImGuiColorEditFlags_NoTooltip, ImVec2(12, 12));
    ImGui::SameLine();
    ImGui::Text("%s", label);
  };
  if (panelTracking()) {  // the legend's rectangle for the window test, when it appears or moves
    static ImVec2 last{-1, -1};
    const ImVec2 pos = ImGui::GetWindowPos(), size = ImGui::GetWindowSize(), sc = ImGui::GetIO().DisplayFramebufferScale;
    if (pos.x != last.x || pos.y != last.y) {
      std::printf("ui legend %d %d %d %d\n", int(pos.x * sc.x), int(pos.y * sc.y), int((pos.x + size.x) * sc.x),
                  int((pos.y + size.y) * sc.y));
      std::fflush(stdout);
      last = pos;
    }
  }
  if (facts.errorMap) {  // core/compare.hpp's map: grey by the largest channel error, red past the threshold
    ImGui::Text("error map, per pixel: the largest channel error in 8-bit steps");
    swatch(ImVec4(0, 0, 0, 1), "0: black");
    ImGui::SameLine();
    swatch(ImVec4(1, 1, 1, 1), "white: 3 steps");
    ImGui::SameLine();
    swatch(ImVec4(1, 0, 0, 1), "red: more, beyond a 3x3 neighbourhood");
  } else if (mode == VIEW_MIP_LEVEL) {  // shaders/debug.frag's mipColor
    static const ImVec4 k[] = {{0, 0, 1, 1},    {0, 1, 1, 1}, {0, 1, 0, 1}, {1, 1, 0, 1},
                               {1, 0.5f, 0, 1}, {1, 0, 0, 1}, {1, 0, 1, 1}, {1, 1, 1, 1}};
    static const char* names[] = {"0", "1", "2", "3", "4", "5", "6", "7+"};
    ImGui::Text("mip level:");
    for (int i = 0; i < 8; ++i) {
      ImGui::SameLine();
      swatch(k[i], names[i]);
    }
    ImGui::SameLine();
    swatch(ImVec4(0.5f, 0.5f, 0.5f, 1), "no texture");
  } else {
    ImGui::Text("linear depth: black 0, white %.4g units (the far plane) along the view axis", facts.depthFar);
  }
  ImGui::End();
}

}  // namespace rtr::view
