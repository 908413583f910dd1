// The windowed viewer: GLFW window, input and camera; the frames themselves are view_frames.cpp's.
#include <algorithm>
#include <chrono>
#include <memory>
#include <cstdio>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "camera_controller.hpp"
#include "shader_watch.hpp"
#include "view_frames.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "options.hpp"
#include "scene/framing.hpp"
#include "scene/load.hpp"
#include "vk/check.hpp"
#include "vk/context.hpp"

namespace rtr::view {
namespace {

struct App {
  CameraController camera{{}, {}};
  render::RenderSettings settings;
  bool overlay = false, resized = false;
  // Ray tracer (FORMATS.md §2's toggles, on keys that do not clash with the view modes).
  bool traceRequested = false, errorMapRequested = false, reframeRequested = false;
  trace::Shading traceShading = trace::Shading::Phong;
  bool traceShadows = true, traceReflections = true, traceOrtho = false;
};

void onKey(GLFWwindow* w, int key, int, int action, int) {
  App& app = *static_cast<App*>(glfwGetWindowUserPointer(w));
  if (action == GLFW_REPEAT) return;
  const bool down = action == GLFW_PRESS;
  switch (key) {  // held keys: state from press/release events
    case GLFW_KEY_W: app.camera.setKey(Move::Forward, down); return;
    case GLFW_KEY_S: app.camera.setKey(Move::Back, down); return;
    case GLFW_KEY_A: app.camera.setKey(Move::Left, down); return;
    case GLFW_KEY_D: app.camera.setKey(Move::Right, down); return;
    case GLFW_KEY_E: app.camera.setKey(Move::Up, down); return;
    case GLFW_KEY_Q: app.camera.setKey(Move::Down, down); return;
    case GLFW_KEY_LEFT_SHIFT: case GLFW_KEY_RIGHT_SHIFT: app.camera.setKey(Move::Fast, down); return;
    case GLFW_KEY_LEFT_CONTROL: case GLFW_KEY_RIGHT_CONTROL: app.camera.setKey(Move::Slow, down); return;
    default: break;
  }
  if (!down) return;
  if (key >= GLFW_KEY_1 && key <= GLFW_KEY_7) app.settings.mode = key - GLFW_KEY_0;
  else if (key == GLFW_KEY_8) app.settings.mode = VIEW_BRDF_D;
  else if (key == GLFW_KEY_9) app.settings.mode = VIEW_BRDF_F;
  else if (key == GLFW_KEY_0) app.settings.mode = VIEW_BRDF_G;
  else if (key == GLFW_KEY_MINUS) app.settings.mode = VIEW_DIFFUSE;
  else if (key == GLFW_KEY_EQUAL) app.settings.mode = VIEW_SPECULAR;
  else if (key == GLFW_KEY_M) app.settings.mosaic = render::MosaicMode((int(app.settings.mosaic) + 1) % 3);
  else if (key == GLFW_KEY_LEFT_BRACKET) app.settings.lodBias -= 0.5f;
  else if (key == GLFW_KEY_RIGHT_BRACKET) app.settings.lodBias += 0.5f;
  else if (key == GLFW_KEY_F) app.reframeRequested = true;
  else if (key == GLFW_KEY_C) std::printf("--camera %s\n", formatPose(app.camera.pose()).c_str()), std::fflush(stdout);
  else if (key == GLFW_KEY_F1 || key == GLFW_KEY_H) app.overlay = !app.overlay;
  else if (key == GLFW_KEY_R) app.traceRequested = true;
  else if (key == GLFW_KEY_X) app.errorMapRequested = true;
  else if (key == GLFW_KEY_T) app.traceShading = trace::Shading((int(app.traceShading) + 1) % 3);  // phong, pbr, normals
  else if (key == GLFW_KEY_Y) app.traceShadows = !app.traceShadows;
  else if (key == GLFW_KEY_U) app.traceReflections = !app.traceReflections;
  else if (key == GLFW_KEY_O) app.traceOrtho = !app.traceOrtho;
  else if (key == GLFW_KEY_ESCAPE) glfwSetWindowShouldClose(w, GLFW_TRUE);
}

void onMouseButton(GLFWwindow* w, int button, int action, int) {
  App& app = *static_cast<App*>(glfwGetWindowUserPointer(w));
  if (button == GLFW_MOUSE_BUTTON_RIGHT && action == GLFW_PRESS) {
    app.camera.toggleMouseLook();
    glfwSetInputMode(w, GLFW_CURSOR, app.camera.mouseLook() ? GLFW_CURSOR_DISABLED : GLFW_CURSOR_NORMAL);
  }
}

void onCursor(GLFWwindow* w, double x, double y) { static_cast<App*>(glfwGetWindowUserPointer(w))->camera.mouseMoved(x, y); }
void onResize(GLFWwindow* w, int, int) { static_cast<App*>(glfwGetWindowUserPointer(w))->resized = true; }

const char* modeName(int m) {
  static const char* names[] = {"", "shaded", "mip level", "linear depth", "depth derivatives", "normal", "view dir",
                                "light dir", "BRDF D", "BRDF F", "BRDF G", "diffuse", "specular", "albedo"};
  return m >= 1 && m <= VIEW_COUNT ? names[m] : "?";
}

struct GlfwSession {
  GlfwSession() {
    if (!glfwInit()) throw Error("cannot initialise GLFW (no display? use --headless)");
  }
  ~GlfwSession() { glfwTerminate(); }
};

const char* const kKeyHelp =
    "W/S/A/D/E/Q move, Shift/Ctrl faster/slower, right mouse: mouse-look\n"
    "1-7 views, 8/9/0 BRDF D/F/G, -/= diffuse/specular, M mosaic\n"
    "[ ] LOD bias, F frame the scene, C print pose, F1/H this overlay, Esc quit\n"
    "R ray-trace (T shading, Y shadows, U reflections, O ortho)\n"
    "X error map: raster vs CPU trace of the same model";

}  // namespace

int runWindowed(const ViewOptions& o) {
  GlfwSession glfw;
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  App app;
  Scene scene = loadScene(o.scene, o.load);
  app.settings = sceneSettings(o, scene);

  uint32_t extCount = 0;
  const char** exts = glfwGetRequiredInstanceExtensions(&extCount);
  if (!exts) throw Error("GLFW found no Vulkan surface support");
  vk::ContextOptions co = contextOptions(o);
  co.instanceExtensions.assign(exts, exts + extCount);
  co.presentation = true;
  vk::Context ctx(co);
  checkSizeFits(o, ctx);
  const DeviceChoice choice = chooseForDevice(o, ctx);
  app.settings.shading = choice.shading;

  GLFWwindow* window = glfwCreateWindow(int(o.width), int(o.height), "rtr-view", nullptr, nullptr);
  if (!window) throw Error("cannot create a window");
  struct WindowGuard { GLFWwindow* w; ~WindowGuard() { glfwDestroyWindow(w); } } windowGuard{window};
  VkSurfaceKHR surface;
  VK_CHECK(glfwCreateWindowSurface(ctx.instance(), window, nullptr, &surface));
  struct SurfaceGuard { VkInstance i; VkSurfaceKHR s; ~SurfaceGuard() { vkDestroySurfaceKHR(i, s, nullptr); } } surfaceGuard{ctx.instance(), surface};

  glfwSetWindowUserPointer(window, &app);
  glfwSetKeyCallback(window, onKey);
  glfwSetMouseButtonCallback(window, onMouseButton);
  glfwSetCursorPosCallback(window, onCursor);
  glfwSetFramebufferSizeCallback(window, onResize);

  const Bounds bounds = scene.bounds();
  CameraSpeeds speeds;
  // Cross the scene in about 5 s with Shift held.
  if (!bounds.empty()) speeds.base = glm::length(bounds.extent()) / (5.0f * speeds.fastFactor);
  app.camera = CameraController(startPose(o, scene), speeds);
  // Course scenes light themselves with "*light*" geometry (Blinn-Phong); others use the renderer's light.
  const bool geometryLights = std::any_of(scene.materials.begin(), scene.materials.end(),
                                          [](const Material& m) { return m.flags & kMaterialLight; });
  app.traceShading = geometryLights ? trace::Shading::Phong : trace::Shading::Pbr;
  // The speed depends on the scene; printed so that users (and the window test) know what W does.
  std::fprintf(stderr, "rtr-view: move speed %.9g units/s (Shift x%g, Ctrl x%g)\n", speeds.base, speeds.fastFactor,
               speeds.slowFactor);

  render::GpuScene gpuScene(ctx, scene, choice.mips);
  {
    ViewFrames frames(ctx, surface, {o.width, o.height}, gpuScene);
    TraceOverlay traced(scene);
    std::unique_ptr<ShaderWatcher> watcher;
    if (o.watch) watcher = std::make_unique<ShaderWatcher>(RTR_SHADER_SOURCE_DIR);
    std::string shaderError;
    double watchTimer = 0;
    std::string overlayText;

    auto last = std::chrono::steady_clock::now();
    double titleTimer = 0, cpuFrameMs = 0;
    uint64_t frameNumber = 0;
    while (!glfwWindowShouldClose(window)) {
      glfwPollEvents();
      int fbw = 0, fbh = 0;
      glfwGetFramebufferSize(window, &fbw, &fbh);
      // Minimised: pause rendering until restored. A minimised window has a zero framebuffer on Windows
      // only; on X11 it keeps its size, and the iconified state is the window manager's WM_STATE.
      if (fbw == 0 || fbh == 0 || glfwGetWindowAttrib(window, GLFW_ICONIFIED)) {
        glfwWaitEvents();
        last = std::chrono::steady_clock::now();
        continue;
      }
      if (app.resized) frames.markStale(), app.resized = false;
      const auto now = std::chrono::steady_clock::now();
      const float dt = std::chrono::duration<float>(now - last).count();
      last = now;
      cpuFrameMs = 0.9 * cpuFrameMs + 0.1 * dt * 1000.0;
      app.camera.update(dt);
      watchTimer += dt;
      if (watcher && watchTimer > 0.5) {  // hot reload: a failure keeps the running pipelines
        watchTimer = 0;
        std::string err;
        if (watcher->poll(err)) {
          try {
            frames.renderer().rebuildPipelines();
            shaderError.clear();
            std::fprintf(stderr, "rtr-view: shaders reloaded\n");
          } catch (const std::exception& e) {
            err = e.what();
          }
        }
        if (!err.empty()) {
          shaderError = err;
          std::fprintf(stderr, "rtr-view: shader reload failed, keeping the previous pipelines:\n%s\n", err.c_str());
        }
      }

      const VkExtent2D e = frames.extent();
      if (app.reframeRequested) {  // F: the whole scene in view, as a scene without a stored view starts
        app.reframeRequested = false;
        app.camera.setPose(framingPose(scene, o.lens, float(e.width) / float(std::max(1u, e.height))));
      }
      auto traceSettings = [&] {
        trace::TraceSettings ts;
        ts.width = e.width;
        ts.height = e.height;
        ts.pose = app.camera.pose();
        ts.lens = fitDepthRange(o.lens, bounds, app.camera.pose());
        ts.lens.orthographic = app.traceOrtho;
        ts.shading = app.traceShading;
        ts.shadows = app.traceShadows;
        ts.bounces = app.traceReflections ? trace::N_BOUNCES : 0;
        ts.lights = app.settings.lights;
        ts.lodBias = app.settings.lodBias;
        return ts;
      };
      if (app.traceRequested) {  // R: trace this view; R again while shown hides it
        app.traceRequested = false;
        if (traced.visible()) traced.stop();
        else traced.start(traceSettings());
      }
      // X: this frame is rendered shaded without mosaic and read back, then traced with the renderer's model
      // (PBR, no shadows, no reflections, perspective) and compared; X again while shown hides it.
      bool captureRaster = false;
      if (app.errorMapRequested) {
        app.errorMapRequested = false;
        if (traced.visible()) traced.stop();
        else if (frames.canReadBack()) captureRaster = true;
        else std::fprintf(stderr, "rtr-view: this surface's images cannot be read back for the error map\n");
      }
      const bool takeShot = !o.screenshot.empty() && frameNumber + 1 == uint64_t(std::max(1, o.frames));
      if (takeShot && !frames.canReadBack()) throw Error("this surface's images cannot be read back for --screenshot");
      ViewFrameInput in{app.camera.pose(), fitDepthRange(o.lens, bounds, app.camera.pose()), app.settings, &traced,
                        app.overlay ? &overlayText : nullptr, takeShot || captureRaster};
      if (captureRaster) {
        in.settings.mode = VIEW_SHADED;
        in.settings.mosaic = render::MosaicMode::Off;
      }
      ImageRGBA8 shot;
      if (!frames.frame({uint32_t(fbw), uint32_t(fbh)}, in, &shot)) continue;  // swapchain out of date: next time
      if (takeShot) {
        saveImage(o.screenshot, shot, {o.force ? Replace::Yes : Replace::No, true});
        std::printf("%s\n", std::filesystem::absolute(o.screenshot).c_str());
        glfwSetWindowShouldClose(window, GLFW_TRUE);
      }
      if (captureRaster) {  // traced on the CPU's cores while frames go on; shown when done
        trace::TraceSettings ts = traceSettings();
        ts.shading = trace::Shading::Pbr;
        ts.shadows = false;
        ts.bounces = 0;
        ts.lens.orthographic = false;
        traced.start(ts, std::move(shot));
      }
      ++frameNumber;

      titleTimer += dt;
      if (titleTimer > 0.25) {  // the overlay's text (drawn in the frame when F1/H is on) and the window title
        titleTimer = 0;
        std::vector<std::string> lines;
        char buf[160];
        std::snprintf(buf, sizeof buf, "mode %d | %s | mosaic %s | lod bias %.1f", app.settings.mode,
                      modeName(app.settings.mode), render::toString(app.settings.mosaic), app.settings.lodBias);
        lines.push_back(buf);
        std::snprintf(buf, sizeof buf, "CPU frame %.2f ms", cpuFrameMs);
        lines.push_back(buf);
        std::string gpu = "GPU";
        for (const auto& [name, ms] : frames.gpuTimes()) {
          std::snprintf(buf, sizeof buf, " | %s %.3f ms", name.c_str(), ms);
          gpu += buf;
        }
        lines.push_back(gpu);
        if (traced.visible()) lines.push_back(traced.status());
        if (!shaderError.empty()) lines.push_back("SHADER ERROR: " + shaderError);
        std::string title = "rtr-view";
        for (const std::string& l : lines) title += " | " + l.substr(0, l.find('\n'));
        glfwSetWindowTitle(window, title.c_str());
        overlayText.clear();
        for (const std::string& l : lines) overlayText += l + "\n";
        overlayText += kKeyHelp;
      }
    }
  }
  return 0;
}

}  // namespace rtr::view
