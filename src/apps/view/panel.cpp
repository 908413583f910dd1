// The windowed viewer's settings panel: every setting that has a key, the lights, the camera, the tracer,
// scene facts and the frame-time graphs.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>

#include <imgui.h>

#include "frame.h"
#include "view_state.hpp"

namespace rtr::view {
namespace {

bool tracking = false;  // setPanelTracking

void track(const std::string& id) {
  if (!tracking) return;
  static std::map<std::string, std::array<int, 4>> last;
  const ImVec2 a = ImGui::GetItemRectMin(), b = ImGui::GetItemRectMax(), s = ImGui::GetIO().DisplayFramebufferScale;
  const std::array<int, 4> r{int(a.x * s.x), int(a.y * s.y), int(b.x * s.x), int(b.y * s.y)};
  if (last[id] == r) return;
  last[id] = r;
  std::printf("ui %s %d %d %d %d\n", id.c_str(), r[0], r[1], r[2], r[3]);
  std::fflush(stdout);
}

template <class Enum>
bool radio(const char* label, Enum& value, Enum option) {
  const bool changed = ImGui::RadioButton(label, value == option);
  track(label);
  if (changed) value = option;
  return changed;
}

// Intensity and rotation take effect when the slider is let go: each change prefilters the environment
// again (milliseconds on a GPU, seconds on lavapipe). The blur is a setting of every frame.
void environmentSection(ViewState& s) {
  ImGui::SliderFloat("intensity", &s.envIntensity, 0.0f, 100.0f, "%.3g", ImGuiSliderFlags_Logarithmic);
  s.envChanged |= ImGui::IsItemDeactivatedAfterEdit();
  track("env-intensity");
  ImGui::SliderFloat("rotation", &s.envRotationDeg, -180.0f, 180.0f, "%.0f deg");
  s.envChanged |= ImGui::IsItemDeactivatedAfterEdit();
  track("env-rotation");
  if (s.settings.backdropBlur >= 0.0f) {
    ImGui::SliderFloat("background blur", &s.settings.backdropBlur, 0.0f, 1.0f, "%.2f");
    track("env-blur");
  } else {
    ImGui::TextDisabled("background: the --background colour");
  }
}

void graph(const char* label, const std::deque<float>& values) {
  if (values.empty()) return;
  std::vector<float> v(values.begin(), values.end()), sorted = v;
  std::sort(sorted.begin(), sorted.end());
  char overlay[96];
  std::snprintf(overlay, sizeof overlay, "%s: min %.3f, median %.3f ms", label, sorted.front(), sorted[sorted.size() / 2]);
  ImGui::PlotLines("##graph", v.data(), int(v.size()), 0, overlay, 0.0f, sorted.back() * 1.2f + 1e-3f,
                   ImVec2(ImGui::GetContentRegionAvail().x, 40));
}

void lightsSection(ViewState& s) {
  LightRig& rig = s.settings.lights;
  for (size_t i = 0; i < rig.lights.size(); ++i) {
    Light& l = rig.lights[i];
    ImGui::PushID(int(i));
    const char* kind = l.kind == Light::Kind::Area ? "area" : l.kind == Light::Kind::Headlight ? "headlight" : "point";
    ImGui::Text("light %zu (%s)", i, kind);
    if (l.kind != Light::Kind::Headlight) {  // a headlight sits at the camera
      glm::vec3 p = l.position;
      if (ImGui::DragFloat3("position", &p.x, 0.05f)) {
        l.corner += p - l.position;  // an area light moves as a whole
        l.position = p;
      }
    }
    // The stored colour is colour x intensity: edited apart.
    float intensity = std::max({l.color.r, l.color.g, l.color.b});
    glm::vec3 c = intensity > 0 ? l.color / intensity : glm::vec3(1.0f);
    const bool colour = ImGui::ColorEdit3("colour", &c.x);
    const bool strength = ImGui::DragFloat("intensity", &intensity, 0.01f, 0.0f, 1e6f);
    if (colour || strength) l.color = c * std::max(0.0f, intensity);
    if (l.kind != Light::Kind::Headlight) ImGui::Checkbox("inverse-square falloff", &l.falloff);
    ImGui::PopID();
  }
  ImGui::ColorEdit3("ambient", &rig.ambient.x, ImGuiColorEditFlags_Float | ImGuiColorEditFlags_HDR);
}

void cameraSection(ViewState& s) {
  CameraController& cam = s.camera;
  int mode = int(cam.mode());
  ImGui::Text("camera:");
  ImGui::SameLine();
  const bool fly = ImGui::RadioButton("fly", &mode, int(CameraMode::Fly));
  track("camera:fly");
  ImGui::SameLine();
  const bool orbit = ImGui::RadioButton("orbit", &mode, int(CameraMode::Orbit));
  track("camera:orbit");
  if (fly || orbit) cam.setMode(CameraMode(mode));
  ImGui::TextDisabled(mode == int(CameraMode::Fly) ? "W/S/A/D/E/Q move, right mouse: mouse-look"
                                                   : "left-drag turn, scroll zoom, middle-drag pan");
  CameraPose p = cam.pose();
  bool changed = ImGui::DragFloat3("position", &p.position.x, 0.05f);
  changed |= ImGui::DragFloat("yaw", &p.yawDeg, 0.5f);
  changed |= ImGui::DragFloat("pitch", &p.pitchDeg, 0.5f, -89.0f, 89.0f);
  if (changed) cam.setPose(p);
  char pose[160];
  std::snprintf(pose, sizeof pose, "--camera %s", formatPose(p).c_str());
  ImGui::InputText("##pose", pose, sizeof pose, ImGuiInputTextFlags_ReadOnly);  // selectable, copyable
  ImGui::SameLine();
  if (ImGui::Button("copy")) ImGui::SetClipboardText(pose);
  ImGui::DragFloat("speed (units/s)", &cam.speeds().base, 0.01f, 1e-4f, 1e6f, "%.4g", ImGuiSliderFlags_Logarithmic);
  ImGui::SliderFloat("fov (degrees)", &s.lens.fovYDeg, 5.0f, 150.0f);
  if (ImGui::Button("frame scene (F)")) s.reframeRequested = true;
  ImGui::SameLine();
  if (ImGui::Button("start pose (Home)")) s.homeRequested = true;
}

void tracerSection(ViewState& s, const PanelFacts& facts) {
  if (ImGui::Button("trace view (R)")) s.traceRequested = true;
  ImGui::SameLine();
  if (ImGui::Button("error map (X)")) s.errorMapRequested = true;
  int shading = int(s.traceShading);
  if (ImGui::Combo("shading (T)", &shading, "Phong\0PBR\0normals\0")) s.traceShading = trace::Shading(shading);
  ImGui::Checkbox("shadows (Y)", &s.traceShadows);
  ImGui::SameLine();
  ImGui::Checkbox("reflections (U)", &s.traceReflections);
  ImGui::SameLine();
  ImGui::Checkbox("ortho (O)", &s.traceOrtho);
  if (!facts.traceStatus.empty()) ImGui::TextWrapped("%s", facts.traceStatus.c_str());
}

}  // namespace

void setPanelTracking(bool on) { tracking = on; }
bool panelTracking() { return tracking; }

const char* modeName(int m) {
  static const char* names[] = {
      "",       "shaded", "mip level", "linear depth", "depth derivatives", "normal", "view dir",    "light dir",
      "BRDF D", "BRDF F", "BRDF G",    "diffuse",      "specular",          "albedo", "env diffuse", "env specular"};
  static_assert(std::size(names) == VIEW_COUNT + 1);
  return m >= 1 && m <= VIEW_COUNT ? names[m] : "?";
}

void FrameHistory::add(float cpu, const std::vector<std::pair<std::string, double>>& gpu) {
  auto push = [](std::deque<float>& d, float v) {
    d.push_back(v);
    if (d.size() > kFrames) d.pop_front();
  };
  push(cpuMs, cpu);
  for (const auto& [name, ms] : gpu) push(gpuMs[name], float(ms));
}

void drawPanel(ViewState& s, const PanelFacts& facts, const FrameHistory& history) {
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  ImGui::SetNextWindowSize(ImVec2(std::min(display.x - 16, 420.0f), std::min(display.y - 16, 640.0f)), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowCollapsed(true, ImGuiCond_FirstUseEver);  // the title bar only, until clicked
  const bool open = ImGui::Begin("rtr-view settings and keys (F1 hides)");
  if (tracking) {  // the window's rectangle, open or collapsed
    const ImVec2 a = ImGui::GetWindowPos(), b = ImGui::GetWindowSize(), sc = ImGui::GetIO().DisplayFramebufferScale;
    static std::array<int, 4> last{};
    const std::array<int, 4> r{int(a.x * sc.x), int(a.y * sc.y), int((a.x + b.x) * sc.x), int((a.y + b.y) * sc.y)};
    if (r != last) std::printf("ui panel %d %d %d %d\n", r[0], r[1], r[2], r[3]), std::fflush(stdout), last = r;
  }
  if (!open) {
    ImGui::End();
    return;
  }
  if (!s.message.empty()) {
    ImGui::TextColored(s.messageIsError ? ImVec4(1, 0.35f, 0.3f, 1) : ImVec4(0.6f, 1, 0.6f, 1), "%s", s.message.c_str());
    track("message");
  }
  if (!facts.shaderError.empty()) ImGui::TextColored(ImVec4(1, 0.35f, 0.3f, 1), "shader error: %s", facts.shaderError.c_str());
  if (facts.texturesLoading) {  // a bar while a deferred load streams in (materials show factors until theirs)
    char label[64];
    std::snprintf(label, sizeof label, "textures %zu/%u (decoded %zu)", facts.texturesIn, facts.textures, facts.texturesDecoded);
    ImGui::ProgressBar(facts.textures ? float(facts.texturesIn) / float(facts.textures) : 0.0f, ImVec2(-1, 0), label);
    track("textures");
  }
  // First, where no open section pushes it out of a small window.
  if (ImGui::Button("screenshot (PNG beside the scene)")) s.screenshotRequested = true;
  track("screenshot");

  if (ImGui::CollapsingHeader("View", ImGuiTreeNodeFlags_DefaultOpen)) {
    if (ImGui::BeginCombo("view", modeName(s.settings.mode))) {
      track("mode");
      for (int m = 1; m <= VIEW_COUNT; ++m) {
        if (ImGui::Selectable(modeName(m), s.settings.mode == m)) s.settings.mode = m;
        track("mode:" + std::to_string(m));
      }
      ImGui::EndCombo();
    } else {
      track("mode");
    }
    ImGui::Text("BRDF term:");
    for (int m : {VIEW_BRDF_D, VIEW_BRDF_F, VIEW_BRDF_G, VIEW_DIFFUSE, VIEW_SPECULAR}) {
      ImGui::SameLine();
      radio(m == VIEW_BRDF_D    ? "D"
            : m == VIEW_BRDF_F  ? "F"
            : m == VIEW_BRDF_G  ? "G"
            : m == VIEW_DIFFUSE ? "diff"
                                : "spec",
            s.settings.mode, m);
    }
    ImGui::Text("mosaic (M):");
    ImGui::SameLine();
    radio("off", s.settings.mosaic, render::MosaicMode::Off);
    ImGui::SameLine();
    radio("compute##mosaic", s.settings.mosaic, render::MosaicMode::Compute);
    ImGui::SameLine();
    radio("graphics", s.settings.mosaic, render::MosaicMode::Graphics);
    ImGui::Text("mips:");
    ImGui::SameLine();
    s.remipRequested |= radio("blit", s.mips, render::MipMode::Blit);
    ImGui::SameLine();
    s.remipRequested |= radio("compute##mips", s.mips, render::MipMode::Compute);
    ImGui::SameLine();
    s.remipRequested |= radio("auto##mips", s.mips, render::MipMode::Auto);
    ImGui::SameLine();
    ImGui::TextDisabled("%.3f ms GPU", facts.mipGpuMs);
    ImGui::SliderFloat("LOD bias", &s.settings.lodBias, -4.0f, 4.0f, "%.2f");
    track("lodbias");
    // Sampler changes take effect on the next frame (the renderer rewrites its texture descriptors).
    render::SamplerSettings& sampler = s.settings.sampler;
    ImGui::Text("filter:");
    for (auto f : {render::TextureFilter::Trilinear, render::TextureFilter::NearestMip, render::TextureFilter::Nearest}) {
      ImGui::SameLine();
      radio(enumName(f), sampler.filter, f);
    }
    if (facts.maxAnisotropy > 1) {
      ImGui::SliderFloat("anisotropy", &sampler.anisotropy, 1.0f, facts.maxAnisotropy, sampler.anisotropy > 1 ? "%.0fx" : "off");
      track("anisotropy");
      sampler.anisotropy = std::clamp(std::round(sampler.anisotropy), 1.0f, facts.maxAnisotropy);
    } else {
      ImGui::TextDisabled("anisotropy: not supported by the device");
    }
    ImGui::Text("shading path: %s", enumName(s.settings.shading));
  }
  if (ImGui::CollapsingHeader("Lights")) lightsSection(s);
  if (s.hasEnvironment) {
    const bool open = ImGui::CollapsingHeader("Environment");
    track("environment");
    if (open) environmentSection(s);
  }
  if (ImGui::CollapsingHeader("Camera")) cameraSection(s);
  if (ImGui::CollapsingHeader("Ray tracer")) tracerSection(s, facts);
  if (ImGui::CollapsingHeader("Scene")) {
    ImGui::TextWrapped("%s", facts.scenePath.c_str());
    ImGui::Text("%u meshes, %u materials, %u textures, %u triangles", facts.meshes, facts.materials, facts.textures,
                facts.triangles);
    ImGui::TextDisabled(
        "drop an .obj, .obj.zst, .rtrscene or .comp5892mesh on the window to load it; Left/Right: the "
        "other files of the command line or folder; F5 reads the file again");
  }
  if (ImGui::CollapsingHeader("Timing", ImGuiTreeNodeFlags_DefaultOpen)) {
    graph("CPU frame", history.cpuMs);
    for (const auto& [name, values] : history.gpuMs) {
      ImGui::PushID(name.c_str());
      graph(name.c_str(), values);
      ImGui::PopID();
    }
  }
  if (ImGui::CollapsingHeader("Keys (as rtr-view --help lists them)")) {
    for (const auto& [key, what] : keyList()) {
      ImGui::Text("%-22s", key);
      ImGui::SameLine();
      ImGui::TextWrapped("%s", what);
    }
  }
  const bool startupOpen = ImGui::CollapsingHeader("Start-up");  // the phases --timings prints
  track("start-up");
  if (startupOpen && facts.startup && !facts.startup->empty()) {
    for (const auto& [name, ms] : *facts.startup) ImGui::Text("%8.1f ms  %s", ms, name.c_str());
    ImGui::Text("%8.1f ms  first frame on screen, from process start", facts.startupTotalMs);
    track("start-up:total");
    if (facts.texturesInAtMs > 0) ImGui::Text("%8.1f ms  textures in, from process start", facts.texturesInAtMs);
    else if (facts.textures) ImGui::TextDisabled("textures still loading");
  }
  ImGui::End();
}

}  // namespace rtr::view
