// The windowed viewer: GLFW window, input, camera, the settings panel and dropped files; the frames
// themselves are view_frames.cpp's.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <future>
#include <memory>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>

#include "core/error.hpp"
#include "core/image.hpp"
#include "options.hpp"
#include "render/startup.hpp"
#include "scene/framing.hpp"
#include "scene/load.hpp"
#include "shader_watch.hpp"
#include "view_frames.hpp"
#include "view_state.hpp"
#include "vk/check.hpp"
#include "vk/context.hpp"
#include "vk/pipeline_cache.hpp"

namespace rtr::view {
namespace {

ViewState& state(GLFWwindow* w) { return *static_cast<ViewState*>(glfwGetWindowUserPointer(w)); }

void onKey(GLFWwindow* w, int key, int, int action, int) {
  ViewState& app = state(w);
  if (action == GLFW_REPEAT) return;
  const bool down = action == GLFW_PRESS;
  if (down && ImGui::GetIO().WantCaptureKeyboard) return;  // typing into the panel (releases still count)
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
  else if (key == GLFW_KEY_HOME) app.homeRequested = true;
  else if (key == GLFW_KEY_C) {
    std::printf("--camera %s\n", formatPose(app.camera.pose()).c_str());
    if (app.camera.mode() == CameraMode::Orbit) {
      const glm::vec3 t = app.camera.orbitTarget();
      std::printf("orbit target %.9g,%.9g,%.9g distance %.9g\n", t.x, t.y, t.z, app.camera.orbitDistance());
    }
    std::fflush(stdout);
  }
  else if (key == GLFW_KEY_F1 || key == GLFW_KEY_H) app.panel = !app.panel;
  else if (key == GLFW_KEY_R) app.traceRequested = true;
  else if (key == GLFW_KEY_X) app.errorMapRequested = true;
  else if (key == GLFW_KEY_T) app.traceShading = trace::Shading((int(app.traceShading) + 1) % 3);  // phong, pbr, normals
  else if (key == GLFW_KEY_Y) app.traceShadows = !app.traceShadows;
  else if (key == GLFW_KEY_U) app.traceReflections = !app.traceReflections;
  else if (key == GLFW_KEY_O) app.traceOrtho = !app.traceOrtho;
  else if (key == GLFW_KEY_ESCAPE) glfwSetWindowShouldClose(w, GLFW_TRUE);
}

void onMouseButton(GLFWwindow* w, int button, int action, int) {
  ViewState& app = state(w);
  if (action == GLFW_RELEASE) {  // a drag ends wherever the button is released
    if (button != GLFW_MOUSE_BUTTON_RIGHT) app.camera.setDrag(Drag::None);
    return;
  }
  if (ImGui::GetIO().WantCaptureMouse) return;  // a click on the panel
  if (button == GLFW_MOUSE_BUTTON_RIGHT) {
    app.camera.toggleMouseLook();
    glfwSetInputMode(w, GLFW_CURSOR, app.camera.mouseLook() ? GLFW_CURSOR_DISABLED : GLFW_CURSOR_NORMAL);
  } else if (button == GLFW_MOUSE_BUTTON_LEFT) {
    app.camera.setDrag(Drag::Rotate);
  } else if (button == GLFW_MOUSE_BUTTON_MIDDLE) {
    app.camera.setDrag(Drag::Pan);
  }
}

void onScroll(GLFWwindow* w, double, double dy) {
  ViewState& app = state(w);
  if (!ImGui::GetIO().WantCaptureMouse && app.camera.mode() == CameraMode::Orbit) app.camera.scrolled(dy);
}

void onDrop(GLFWwindow* w, int count, const char** paths) {
  for (int i = 0; i < count; ++i) state(w).drops.push_back(paths[i]);
}

void onCursor(GLFWwindow* w, double x, double y) { state(w).camera.mouseMoved(x, y); }
void onResize(GLFWwindow* w, int, int) { state(w).resized = true; }

// A drop the window test can make (xdotool cannot drag files): RTR_VIEW_TEST_DROP names a file whose
// lines are paths; once it appears it is read, removed and handed to the drop callback.
void pollTestDrop(GLFWwindow* w) {
  static const char* file = std::getenv("RTR_VIEW_TEST_DROP");
  if (!file || !std::filesystem::exists(file)) return;
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);)
    if (!l.empty()) lines.push_back(l);
  std::filesystem::remove(file);
  std::vector<const char*> paths;
  for (const auto& l : lines) paths.push_back(l.c_str());
  onDrop(w, int(paths.size()), paths.data());
}

struct GlfwSession {
  GlfwSession() {
    if (!glfwInit()) throw Error("cannot initialise GLFW (no display? use --headless)");
  }
  ~GlfwSession() { glfwTerminate(); }
};

// Dear ImGui for one window: its layout in the user's config folder, sized by the monitor's content scale.
struct ImGuiSession {
  std::string ini;
  explicit ImGuiSession(GLFWwindow* window) {
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;
    const char* xdg = std::getenv("XDG_CONFIG_HOME");
    const char* home = std::getenv("HOME");
    if ((xdg && *xdg) || (home && *home)) {
      const std::filesystem::path dir = (xdg && *xdg) ? std::filesystem::path(xdg) / "rtr"
                                                      : std::filesystem::path(home) / ".config" / "rtr";
      std::error_code ec;
      std::filesystem::create_directories(dir, ec);
      if (!ec) ini = (dir / "imgui.ini").string(), io.IniFilename = ini.c_str();
    }
    float xs = 1, ys = 1;
    glfwGetWindowContentScale(window, &xs, &ys);
    ImFontConfig font;
    font.SizePixels = 13.0f * std::max(1.0f, xs);
    io.Fonts->AddFontDefault(&font);
    ImGui::GetStyle().ScaleAllSizes(std::max(1.0f, xs));
    ImGui_ImplGlfw_InitForVulkan(window, true);  // chains to the callbacks installed before
  }
  ~ImGuiSession() {
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
  }
};

// `scene`'s file name without its extensions, numbered: the first free NAME-N.png beside the scene.
std::string saveShot(const std::filesystem::path& scene, ImageRGBA8 image) {
  const std::filesystem::path dir = std::filesystem::absolute(scene).parent_path();
  std::string base = scene.filename().string();
  base = base.substr(0, base.find('.'));
  for (int n = 1;; ++n) {
    const std::filesystem::path out = dir / (base + "-" + std::to_string(n) + ".png");
    try {
      saveImage(out, image, {Replace::No, true});
      return out.string();
    } catch (const OutputExists&) {  // never overwrites: the next number
    }
  }
}

// One scene on the GPU, with everything that refers to it; rebuilt whole on a drop or a mip mode change.
struct Loaded {
  std::unique_ptr<Scene> scene;
  std::unique_ptr<render::GpuScene> gpu;
  std::unique_ptr<ViewFrames> frames;
  std::unique_ptr<TraceOverlay> traced;
  void release(const vk::Context& ctx) {  // children first, the device idle
    VK_CHECK(vkDeviceWaitIdle(ctx.device()));
    traced.reset();
    frames.reset();
    gpu.reset();
  }
  void build(const vk::Context& ctx, VkSurfaceKHR surface, VkExtent2D extent, render::MipMode mips, bool waitTextures) {
    gpu = std::make_unique<render::GpuScene>(ctx, *scene, mips, render::LoadProgress{}, render::GeometryUpload::Auto,
                                             waitTextures ? render::TextureLoad::Wait : render::TextureLoad::Deferred);
    frames = std::make_unique<ViewFrames>(ctx, surface, extent, *gpu);
    traced = std::make_unique<TraceOverlay>(ctx, *scene);
  }
};

// Camera, speeds and lights for a newly loaded scene (--camera applies to the first scene only).
void startScene(ViewState& app, const ViewOptions& o, const Scene& scene) {
  const Bounds bounds = scene.bounds();
  CameraSpeeds speeds;
  // Cross the scene in about 5 s with Shift held.
  if (!bounds.empty()) speeds.base = glm::length(bounds.extent()) / (5.0f * speeds.fastFactor);
  app.startPose = startPose(o, scene);
  const CameraMode mode = app.camera.mode();
  app.camera = CameraController(app.startPose, speeds);
  app.camera.setMode(mode);
  app.camera.setOrbitDistance(bounds.empty() ? 1.0f : glm::length(bounds.center() - app.startPose.position));
  const render::RenderSettings s = sceneSettings(o, scene);
  app.settings.lights = s.lights;
  // Course scenes light themselves with "*light*" geometry (Blinn-Phong); others use the renderer's light.
  const bool geometryLights = std::any_of(scene.materials.begin(), scene.materials.end(),
                                          [](const Material& m) { return m.flags & kMaterialLight; });
  app.traceShading = geometryLights ? trace::Shading::Phong : trace::Shading::Pbr;
  // The speed depends on the scene; printed so that users (and the window test) know what W does.
  std::fprintf(stderr, "rtr-view: move speed %.9g units/s (Shift x%g, Ctrl x%g)\n", speeds.base, speeds.fastFactor,
               speeds.slowFactor);
}

}  // namespace

int runWindowed(const ViewOptions& opts) {
  ViewOptions o = opts;
  // Start-up phases, as headless --timings prints them: each runs from the end of the one before, less the
  // pipelines it made (one row of their own), so the rows tile the time to the first frame on screen.
  using Clock = std::chrono::steady_clock;
  render::StartupTimeline timeline;
  std::unique_ptr<vk::Context> ctxHolder;  // made below; its pipeline time is subtracted from each phase
  timeline.add("process start to the viewer (exec, libraries, options)", render::msSinceProcessStart());
  auto phaseStart = Clock::now();
  double pipelineMs = 0;
  const auto phase = [&](const char* name) {
    const double p = ctxHolder ? ctxHolder->pipelineCache().stats().ms : 0;
    timeline.add(name, std::chrono::duration<double, std::milli>(Clock::now() - phaseStart).count() - (p - pipelineMs));
    pipelineMs = p;
    phaseStart = Clock::now();
  };
  GlfwSession glfw;
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  ViewState app;
  Loaded cur;
  cur.scene = std::make_unique<Scene>(loadScene(o.scene, o.load));
  phase("scene file read");
  app.settings = sceneSettings(o, *cur.scene);
  app.lens = o.lens;
  if (o.orbit) app.camera.setMode(CameraMode::Orbit);

  uint32_t extCount = 0;
  const char** exts = glfwGetRequiredInstanceExtensions(&extCount);
  if (!exts) throw Error("GLFW found no Vulkan surface support");
  vk::ContextOptions co = contextOptions(o);
  co.instanceExtensions.assign(exts, exts + extCount);
  co.presentation = true;
  ctxHolder = std::make_unique<vk::Context>(co);
  const vk::Context& ctx = *ctxHolder;
  checkSizeFits(o, ctx);
  const DeviceChoice choice = chooseForDevice(o, ctx);
  app.settings.shading = choice.shading;
  app.mips = choice.mips;
  phase("instance and device");

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
  glfwSetScrollCallback(window, onScroll);
  glfwSetDropCallback(window, onDrop);
  glfwSetFramebufferSizeCallback(window, onResize);
  ImGuiSession imgui(window);
  phase("window, surface and panel");

  startScene(app, o, *cur.scene);
  o.camera.reset();  // a dropped scene starts from its own view
  // The scene's GPU objects go before the surface, window and device, however the loop ends.
  struct Release { Loaded& l; const vk::Context& c; ~Release() { l.release(c); } } releaseGuard{cur, ctx};
  const bool waitTextures = o.waitTextures.value_or(false);
  cur.build(ctx, surface, {o.width, o.height}, app.mips, waitTextures);
  phase(waitTextures ? "scene to the GPU (geometry, textures, mips), swapchain" : "geometry to the GPU, swapchain");
  std::string scenePath = o.scene;
  std::vector<std::pair<std::string, double>> startup;  // for the panel, once the first frame is on screen
  double startupTotal = 0, texturesInAt = 0;

  std::unique_ptr<ShaderWatcher> watcher;
  if (o.watch) watcher = std::make_unique<ShaderWatcher>(RTR_SHADER_SOURCE_DIR);
  std::string shaderError;
  double watchTimer = 0;
  std::future<std::string> shotSaved;  // the panel's screenshot, encoded off the render thread
  std::future<Scene> loading;          // a dropped file, parsed off the render thread
  std::string loadingPath;
  FrameHistory history;

  auto last = std::chrono::steady_clock::now();
  double titleTimer = 0, cpuFrameMs = 0;
  uint64_t frameNumber = 0;
  while (!glfwWindowShouldClose(window)) {
    glfwPollEvents();
    pollTestDrop(window);
    int fbw = 0, fbh = 0;
    glfwGetFramebufferSize(window, &fbw, &fbh);
    // Minimised: pause rendering until restored. A minimised window has a zero framebuffer on Windows
    // only; on X11 it keeps its size, and the iconified state is the window manager's WM_STATE.
    if (fbw == 0 || fbh == 0 || glfwGetWindowAttrib(window, GLFW_ICONIFIED)) {
      glfwWaitEvents();
      last = std::chrono::steady_clock::now();
      continue;
    }
    // Dropped files load on a worker thread while frames go on (the panel says so); the GPU scene is then
    // rebuilt between frames. A failing load keeps the current scene and says why in the panel.
    if (!loading.valid() && !app.drops.empty()) {
      loadingPath = app.drops.back();  // several files at once: the last one
      app.drops.clear();
      app.message = "loading " + loadingPath + " ...", app.messageIsError = false;
      loading = std::async(std::launch::async, [path = loadingPath] { return loadScene(path, {}); });
    }
    std::unique_ptr<Scene> dropped;
    if (loading.valid() && loading.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
      try {
        dropped = std::make_unique<Scene>(loading.get());
        scenePath = loadingPath;
        app.message = "loaded " + loadingPath, app.messageIsError = false;
      } catch (const std::exception& e) {
        app.message = std::string("cannot load: ") + e.what(), app.messageIsError = true;
      }
      std::fprintf(stderr, "rtr-view: %s\n", app.message.c_str());
    }
    if (dropped || std::exchange(app.remipRequested, false)) {
      const VkExtent2D e = cur.frames->extent();
      cur.release(ctx);
      if (dropped) {
        cur.scene = std::move(dropped);
        startScene(app, o, *cur.scene);
      }
      cur.build(ctx, surface, e, app.mips, waitTextures);
      if (cur.gpu->texturesReady())
        std::fprintf(stderr, "rtr-view: mips (%s) %.3f ms GPU\n", enumName(app.mips), cur.gpu->stats().mipGpuMs);
    }
    // Textures decode on worker threads, then upload and get their mips in a submission of their own, while
    // frames go on; then they are taken in between frames.
    if (cur.gpu->updateTextures()) {
      const auto& st = cur.gpu->stats();
      if (texturesInAt == 0) texturesInAt = render::msSinceProcessStart();
      std::fprintf(stderr, "rtr-view: %u textures in: decode %.0f ms (worker threads), upload and mips %.0f ms\n",
                   st.textures, st.decodeMs, st.textureUploadMs);
      std::fprintf(stderr, "rtr-view: mips (%s) %.3f ms GPU\n", enumName(app.mips), st.mipGpuMs);
    }
    ViewFrames& frames = *cur.frames;
    TraceOverlay& traced = *cur.traced;
    const Scene& scene = *cur.scene;
    const Bounds bounds = scene.bounds();

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
          frames.rebuildPipelines();
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
    const float aspect = float(e.width) / float(std::max(1u, e.height));
    if (std::exchange(app.reframeRequested, false)) {  // F: the whole scene in view, as a scene without a stored view starts
      app.camera.setPose(framingPose(scene, app.lens, aspect));
      if (!bounds.empty()) app.camera.setOrbitDistance(glm::length(bounds.center() - app.camera.pose().position));
    }
    if (std::exchange(app.homeRequested, false)) {  // Home: the pose the viewer started from
      app.camera.setPose(app.startPose);
      if (!bounds.empty()) app.camera.setOrbitDistance(glm::length(bounds.center() - app.startPose.position));
    }
    const Lens lens = fitDepthRange(app.lens, bounds, app.camera.pose());
    auto traceSettings = [&] {
      trace::TraceSettings ts;
      ts.width = e.width;
      ts.height = e.height;
      ts.pose = app.camera.pose();
      ts.lens = lens;
      ts.lens.orthographic = app.traceOrtho;
      ts.shading = app.traceShading;
      ts.shadows = app.traceShadows;
      ts.bounces = app.traceReflections ? trace::N_BOUNCES : 0;
      ts.lights = app.settings.lights;
      ts.lodBias = app.settings.lodBias;
      return ts;
    };
    if (std::exchange(app.traceRequested, false)) {  // R: trace this view; R again while shown hides it
      if (traced.visible()) traced.stop();
      else traced.start(traceSettings());
    }
    // X: this frame is rendered shaded without mosaic and read back, then traced with the renderer's model
    // (PBR, no shadows, no reflections, perspective) and compared; X again while shown hides it.
    bool captureRaster = false;
    if (std::exchange(app.errorMapRequested, false)) {
      if (traced.visible()) traced.stop();
      else if (frames.canReadBack()) captureRaster = true;
      else std::fprintf(stderr, "rtr-view: this surface's images cannot be read back for the error map\n");
    }
    const bool takeShot = !o.screenshot.empty() && frameNumber + 1 == uint64_t(std::max(1, o.frames));
    if (takeShot && !frames.canReadBack()) throw Error("this surface's images cannot be read back for --screenshot");
    bool panelShot = std::exchange(app.screenshotRequested, false) && !captureRaster;
    if (panelShot && !frames.canReadBack()) {
      app.message = "this surface's images cannot be read back for a screenshot", app.messageIsError = true;
      panelShot = false;
    }
    if (shotSaved.valid() && shotSaved.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
      try {
        app.message = "saved " + shotSaved.get(), app.messageIsError = false;
      } catch (const std::exception& ex) {
        app.message = std::string("screenshot failed: ") + ex.what(), app.messageIsError = true;
      }
      std::fprintf(stderr, "rtr-view: %s\n", app.message.c_str());
    }

    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    if (app.panel) {
      const auto& st = cur.gpu->stats();
      PanelFacts facts{scenePath, st.meshes, uint32_t(scene.materials.size()), st.textures, st.triangles, st.mipGpuMs,
                       traced.visible() ? traced.status() : std::string(), shaderError, render::maxAnisotropy(ctx),
                       cur.gpu->texturesDecoded(), !cur.gpu->texturesReady(), &startup, startupTotal, texturesInAt};
      drawPanel(app, facts, history);
    }
    ImGui::Render();

    ViewFrameInput in{app.camera.pose(), lens, app.settings, &traced, app.panel ? ImGui::GetDrawData() : nullptr,
                      takeShot || captureRaster || panelShot};
    if (captureRaster) {
      in.settings.mode = VIEW_SHADED;
      in.settings.mosaic = render::MosaicMode::Off;
    }
    ImageRGBA8 shot;
    if (!frames.frame({uint32_t(fbw), uint32_t(fbh)}, in, &shot)) continue;  // swapchain out of date: next time
    history.add(dt * 1000.0f, frames.gpuTimes());
    if (frameNumber == 0) {  // the first frame is on screen (presented; its GPU work waited for)
      VK_CHECK(vkDeviceWaitIdle(ctx.device()));
      phase("first frame (record, GPU, present)");
      startupTotal = render::msSinceProcessStart();
      const vk::PipelineStats ps = ctx.pipelineCache().stats();
      timeline.add("pipeline creation (" + std::to_string(ps.created) + ", " + std::to_string(ps.cacheHits) +
                       " from the cache)", ps.ms);
      startup = timeline.phases();
      if (o.timings) std::fprintf(stderr, "rtr-view: %s", timeline.format(startupTotal).c_str());
    }
    if (takeShot) {
      saveImage(o.screenshot, shot, {o.force ? Replace::Yes : Replace::No, true});
      std::printf("%s\n", std::filesystem::absolute(o.screenshot).c_str());
      glfwSetWindowShouldClose(window, GLFW_TRUE);
    }
    if (panelShot) {
      if (shotSaved.valid()) shotSaved.wait();  // one encode at a time
      shotSaved = std::async(std::launch::async, saveShot, std::filesystem::path(scenePath), std::move(shot));
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
    if (titleTimer > 0.25) {  // the window title: mode, timings, tracer status (the window test reads it)
      titleTimer = 0;
      char buf[160];
      std::snprintf(buf, sizeof buf, "rtr-view | mode %d | %s | mosaic %s | lod bias %.2f | %s x%g | %s | CPU frame %.2f ms",
                    app.settings.mode, modeName(app.settings.mode), enumName(app.settings.mosaic),
                    app.settings.lodBias, enumName(app.settings.sampler.filter), app.settings.sampler.anisotropy,
                    app.camera.mode() == CameraMode::Orbit ? "orbit" : "fly", cpuFrameMs);
      std::string title = buf;
      for (const auto& [name, ms] : frames.gpuTimes()) {
        std::snprintf(buf, sizeof buf, " | %s %.3f ms", name.c_str(), ms);
        title += buf;
      }
      if (traced.visible()) title += " | " + traced.status().substr(0, traced.status().find('\n'));
      if (!shaderError.empty()) title += " | SHADER ERROR: " + shaderError.substr(0, shaderError.find('\n'));
      glfwSetWindowTitle(window, title.c_str());
    }
  }
  return 0;
}

}  // namespace rtr::view
