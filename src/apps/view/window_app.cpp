// The windowed viewer's loop: each frame takes the input, serves the requests it made (drops, reload,
// camera, tracer, screenshots), draws the panel and renders. The parts: window.hpp (window and input),
// scene_camera.hpp, startup_clock.hpp, scene_slot.hpp (drops, reload), screenshots.hpp, panel.cpp;
// the frames themselves are view_frames.cpp's.
#include <chrono>
#include <cstdio>
#include <exception>
#include <memory>
#include <optional>

#include <glm/trigonometric.hpp>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>

#include "brdf.h"
#include "apps/common/cache_options.hpp"
#include "options.hpp"
#include "scene_camera.hpp"
#include "scene_slot.hpp"
#include "screenshots.hpp"
#include "startup_clock.hpp"
#include "vk/check.hpp"
#include "window.hpp"

namespace rtr::view {
namespace {

trace::TraceSettings traceSettings(const ViewState& app, VkExtent2D e, const Lens& lens) {
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
  ts.background = app.settings.background;  // the backdrop colour (the tracer has no environment here)
  if (app.settings.brdf) ts.brdf = *app.settings.brdf == BRDF_GGX ? trace::Brdf::Ggx : trace::Brdf::Beckmann;
  return ts;
}

// R traces this view (again while shown: hides it). X renders this frame shaded without mosaic, reads it
// back and compares it with a trace of the renderer's model (PBR, no shadows, no reflections, perspective);
// X again while shown hides it. True: this frame is the error map's capture.
bool serveTracer(ViewState& app, SceneSlot& slot, const Lens& lens) {
  TraceOverlay& traced = slot.traced();
  if (std::exchange(app.traceRequested, false)) {
    if (traced.visible()) traced.stop();
    else traced.start(traceSettings(app, slot.frames().extent(), lens));
  }
  if (!std::exchange(app.errorMapRequested, false)) return false;
  if (traced.visible()) traced.stop();
  else if (slot.frames().canReadBack()) return true;
  else std::fprintf(stderr, "rtr-view: this surface's images cannot be read back for the error map\n");
  return false;
}

void startErrorMap(ViewState& app, SceneSlot& slot, const Lens& lens, ImageRGBA8 raster) {
  trace::TraceSettings ts = traceSettings(app, slot.frames().extent(), lens);
  ts.shading = trace::Shading::Pbr;
  ts.shadows = false;
  ts.bounces = 0;
  ts.lens.orthographic = false;
  slot.traced().start(ts, std::move(raster));  // traced on the CPU's cores while frames go on
}

}  // namespace

int runWindowed(const ViewOptions& opts) {
  ViewOptions o = opts;
  StartupClock clock;
  // The scene file is read on a worker thread while GLFW, the instance, the device and the window are
  // made: none of them needs the scene.
  SceneRead read(o);
  ViewState app;
  std::optional<GlfwSession> glfw;
  std::optional<vk::Context> device;
  std::optional<Window> windowSlot;
  DeviceChoice choice{};
  std::exception_ptr failed;
  try {
    glfw.emplace();
    vk::ContextOptions co = contextOptions(o);
    co.instanceExtensions = glfw->instanceExtensions();
    co.presentation = true;
    device.emplace(co);
    clock.watch(*device);
    checkSizeFits(o, *device);
    choice = chooseForDevice(o, *device);
    clock.phase("instance and device");
    windowSlot.emplace(*device, o.width, o.height, app);
    setPanelTracking(o.testUi);
    clock.phase("window, surface and panel");
  } catch (...) { failed = std::current_exception(); }
  auto scene = std::make_unique<Scene>(read.take(failed));
  clock.phase("waiting for the scene file read");
  clock.beside("scene file read", read.ms(), "instance, device and window");
  const vk::Context& ctx = *device;
  Window& window = *windowSlot;
  app.settings = sceneSettings(o, *scene);
  app.settings.shading = choice.shading;
  app.settings.clip = choice.computeClip;
  app.mips = choice.mips;
  app.lens = startLens(o, *scene);
  app.panel = o.panel;
  if (o.orbit) app.camera.setMode(CameraMode::Orbit);

  startScene(app, o, *scene);
  o.camera.reset();  // a dropped scene starts from its own view
  const bool waitTextures = o.waitTextures.value_or(false);
  ViewOptions dropped = o;  // a dropped OBJ finds its own MTL
  dropped.load.mtl.reset();
  const std::unique_ptr<TextureCache> textureCache = cli::textureCache(!o.textureCache);
  SceneSlot slot(ctx, window.surface(), std::move(scene), o.files, waitTextures,
                 [dropped](const std::string& path) { return loadForView(dropped, path); });
  slot.setTextureCache(textureCache.get());
  slot.setTextureBatch(size_t(o.textureBatchMb) << 20);
  // The environment as loaded, at intensity 1 and not turned: the panel's controls prefilter it again from this.
  ImageF envRadiance;
  const auto environment = [&] {
    const Environment env(envRadiance, app.envIntensity, glm::radians(app.envRotationDeg));
    return prefilterEnvironment(env, o.env.settings.source, ctx);
  };
  if (o.env.hasEnvironment()) {
    EnvironmentSettings plain = o.env.settings;
    plain.intensity = 1.0f;
    plain.rotationDeg = 0.0f;
    envRadiance = Environment::load(plain).map();
    app.hasEnvironment = true;
    app.envIntensity = o.env.settings.intensity;
    app.envRotationDeg = o.env.settings.rotationDeg;
    slot.setEnvironment(environment());  // before the build: its pipelines are made with it
  }
  slot.build({o.width, o.height}, app.mips, app.settings);
  clock.phase(waitTextures ? "scene to the GPU (geometry, textures, mips), swapchain" : "geometry to the GPU, swapchain",
              slot.pipelineWaitMs());
  clock.add("waiting for the pipelines", slot.pipelineWaitMs());
  const vk::PipelineStats ahead = ctx.pipelineCache().besideStats();
  clock.beside(render::pipelineRow("pipelines made ahead", ahead), ahead.ms, "the scene upload");

  ShaderReload shaders(o.watch);
  Screenshots shots(o);
  FrameHistory history;
  auto last = std::chrono::steady_clock::now();
  double titleTimer = 0, cpuFrameMs = 0;
  for (uint64_t frameNumber = 0; !window.shouldClose();) {
    VkExtent2D fb;
    const bool shown = window.poll(fb);
    window.pollDropFile(o.testDropFile);
    const auto now = std::chrono::steady_clock::now();
    const float dt = std::chrono::duration<float>(now - last).count();
    last = now;
    if (!shown) continue;
    if (slot.update(app)) startScene(app, o, slot.scene());
    if (std::exchange(app.envChanged, false)) {
      try {
        slot.setEnvironment(environment());
      } catch (const Error& e) {  // the environment of before stays
        app.message = e.what();
        app.messageIsError = true;
      }
    }
    if (std::exchange(app.resized, false)) slot.frames().markStale();
    cpuFrameMs = 0.9 * cpuFrameMs + 0.1 * dt * 1000.0;
    app.camera.update(dt);
    shaders.update(dt, slot.frames());

    const VkExtent2D e = slot.frames().extent();
    const Lens lens = serveCamera(app, slot.scene(), float(e.width) / float(std::max(1u, e.height)));
    const bool errorMap = serveTracer(app, slot, lens);
    shots.plan(app, slot.frames(), frameNumber, errorMap);
    shots.collect(app);

    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    if (app.panel) {
      const auto& st = slot.gpu().stats();
      PanelFacts facts{slot.path(),
                       st.meshes,
                       uint32_t(slot.scene().materials.size()),
                       st.textures,
                       st.triangles,
                       st.mipGpuMs,
                       slot.traced().visible() ? slot.traced().status() : std::string(),
                       shaders.error(),
                       render::maxAnisotropy(ctx),
                       slot.gpu().texturesDecoded(),
                       slot.gpu().texturesIn(),
                       !slot.gpu().texturesReady(),
                       clock.phases(),
                       clock.totalMs(),
                       slot.texturesInAtMs(),
                       lens.zFar,
                       slot.traced().errorMapShown()};
      drawPanel(app, facts, history);
      drawLegend(app, facts);
    }
    ImGui::Render();

    ViewFrameInput in{app.camera.pose(),           lens, app.settings, &slot.traced(), app.panel ? ImGui::GetDrawData() : nullptr,
                      errorMap || shots.readBack()};
    if (errorMap) {
      in.settings.mode = VIEW_SHADED;
      in.settings.mosaic = render::MosaicMode::Off;
    }
    ImageRGBA8 shot;
    if (!slot.frames().frame(fb, in, &shot)) continue;  // swapchain out of date: next time
    history.add(dt * 1000.0f, slot.frames().gpuTimes());
    if (frameNumber++ == 0) {  // the first frame is on screen (presented; its GPU work waited for)
      VK_CHECK(vkDeviceWaitIdle(ctx.device()));
      clock.firstFrame(o.timings);
      printPipelineStats(o, ctx);
    }
    if (shots.save(shot, slot.path())) window.close();
    if (errorMap) startErrorMap(app, slot, lens, std::move(shot));

    if ((titleTimer += dt) > 0.25) {  // the window title: mode, timings, tracer status (the window test reads it)
      titleTimer = 0;
      const TraceOverlay& traced = slot.traced();
      window.setTitle(windowTitle(app, slot.frames().gpuTimes(), traced.visible() ? traced.status() : std::string(),
                                  shaders.error(), cpuFrameMs));
    }
  }
  return 0;
}

}  // namespace rtr::view
