// The windowed viewer: GLFW window and input, swapchain, frames in flight, and the renderer.
#include <algorithm>
#include <chrono>
#include <memory>
#include <cstdio>
#include <cstring>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "camera_controller.hpp"
#include "shader_watch.hpp"
#include "trace_overlay.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "options.hpp"
#include "render/text_overlay.hpp"
#include "scene/framing.hpp"
#include "scene/load.hpp"
#include "vk/check.hpp"
#include "vk/context.hpp"
#include "vk/frame_ring.hpp"
#include "vk/swapchain.hpp"

namespace rtr::view {
namespace {

constexpr uint32_t kFramesInFlight = 2;

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

// A read-back presented-format image (BGRA or RGBA UNORM) as RGBA bytes.
ImageRGBA8 readSwapchainImage(const vk::Buffer& buf, VkFormat format, VkExtent2D e) {
  buf.invalidate();
  ImageRGBA8 img{e.width, e.height, std::vector<uint8_t>(size_t(e.width) * e.height * 4)};
  std::memcpy(img.pixels.data(), buf.mapped(), img.pixels.size());
  if (format == VK_FORMAT_B8G8R8A8_UNORM)
    for (size_t i = 0; i < img.pixels.size(); i += 4) std::swap(img.pixels[i], img.pixels[i + 2]);
  return img;
}

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
  vk::ContextOptions co = vk::optionsFromEnvironment();
  if (o.validation) co.validation = true;
  if (!o.device.empty()) co.device = o.device;
  co.instanceExtensions.assign(exts, exts + extCount);
  co.presentation = true;
  vk::Context ctx(co);

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

  render::GpuScene gpuScene(ctx, scene, o.mips);
  {
    vk::Swapchain swapchain(ctx, surface, {o.width, o.height});
    render::Renderer renderer(ctx, gpuScene, kFramesInFlight);

    vk::FrameRing ring(ctx, kFramesInFlight);
    vk::Buffer shot;  // screenshot readback
    TraceOverlay traced(scene);
    std::unique_ptr<ShaderWatcher> watcher;
    if (o.watch) watcher = std::make_unique<ShaderWatcher>(RTR_SHADER_SOURCE_DIR);
    std::string shaderError;
    double watchTimer = 0;
    render::TextOverlay text(ctx, kFramesInFlight);
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
      if (app.resized || swapchain.extent().width != uint32_t(fbw) || swapchain.extent().height != uint32_t(fbh)) {
        swapchain.recreate({uint32_t(fbw), uint32_t(fbh)});
        app.resized = false;
      }
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
            renderer.rebuildPipelines();
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

      if (app.reframeRequested) {  // F: the whole scene in view, as a scene without a stored view starts
        app.reframeRequested = false;
        const VkExtent2D e = swapchain.extent();
        app.camera.setPose(framingPose(scene, o.lens, float(e.width) / float(std::max(1u, e.height))));
      }
      vk::Frame& f = ring.begin();
      uint32_t imageIndex = 0;
      VkResult acq = vkAcquireNextImageKHR(ctx.device(), swapchain.handle(), UINT64_MAX, f.acquired, VK_NULL_HANDLE, &imageIndex);
      if (acq == VK_ERROR_OUT_OF_DATE_KHR) { app.resized = true; continue; }
      if (acq != VK_SUBOPTIMAL_KHR) VK_CHECK(acq);

      auto traceSettings = [&] {
        trace::TraceSettings ts;
        ts.width = swapchain.extent().width;
        ts.height = swapchain.extent().height;
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
      const bool canShot = swapchain.usage() & VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
      // X: this frame is rendered shaded without mosaic and read back, then traced with the renderer's model
      // (PBR, no shadows, no reflections, perspective) and compared; X again while shown hides it.
      bool captureRaster = false;
      if (app.errorMapRequested) {
        app.errorMapRequested = false;
        if (traced.visible()) traced.stop();
        else if (canShot) captureRaster = true;
        else std::fprintf(stderr, "rtr-view: this surface's images cannot be read back for the error map\n");
      }
      const bool takeShot = !o.screenshot.empty() && frameNumber + 1 == uint64_t(std::max(1, o.frames));
      if (takeShot && !canShot) throw Error("this surface's images cannot be read back for --screenshot");
      const bool readBack = takeShot || captureRaster;
      const VkExtent2D e = swapchain.extent();
      if (readBack) shot = vk::Buffer(ctx, VkDeviceSize(e.width) * e.height * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback);
      render::RenderSettings frameSettings = app.settings;
      if (captureRaster) {
        frameSettings.mode = VIEW_SHADED;
        frameSettings.mosaic = render::MosaicMode::Off;
      }

      const bool showTrace = traced.visible() && (swapchain.usage() & VK_IMAGE_USAGE_TRANSFER_DST_BIT);
      const VkImageLayout finalLayout = readBack ? VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL : VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
      const render::RenderTarget target{swapchain.image(imageIndex), swapchain.view(imageIndex), swapchain.format(), e,
                                        showTrace ? VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL : finalLayout};
      const Lens lens = fitDepthRange(o.lens, bounds, app.camera.pose());
      renderer.record(f.cb, f.index, app.camera.pose(), lens, frameSettings, target);
      if (showTrace) {  // the traced image over the raster one
        traced.recordCopy(f, target.image, swapchain.format(), e);
        vk::barrier(f.cb, {{target.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, finalLayout, VK_PIPELINE_STAGE_2_COPY_BIT,
                            VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                            VK_ACCESS_2_TRANSFER_READ_BIT}});
      }
      if (readBack) {
        vk::copyImageToHost(f.cb, target.image, e, shot.handle());
        vk::barrier(f.cb, {{target.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
                            VK_PIPELINE_STAGE_2_COPY_BIT, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE, VK_ACCESS_2_NONE}});
      }
      // The overlay comes last, after any read-back copy: screenshots never contain it.
      if (app.overlay && !readBack)
        text.record(f.cb, f.index, overlayText, target.image, target.view,
                    swapchain.format(), e, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
                    e.width >= 1280 ? 2.0f : 1.0f);  // the pixel font scales by whole pixels only
      // The post pass is the first to touch the swapchain image, in compute or as a colour attachment.
      ring.submit(f, f.acquired, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                  swapchain.renderDone(imageIndex));

      VkSemaphore done = swapchain.renderDone(imageIndex);
      VkSwapchainKHR sc = swapchain.handle();
      VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
      pi.waitSemaphoreCount = 1;
      pi.pWaitSemaphores = &done;
      pi.swapchainCount = 1;
      pi.pSwapchains = &sc;
      pi.pImageIndices = &imageIndex;
      VkResult pr = vkQueuePresentKHR(ctx.queue(), &pi);
      if (pr == VK_ERROR_OUT_OF_DATE_KHR || pr == VK_SUBOPTIMAL_KHR) app.resized = true;
      else VK_CHECK(pr);

      if (readBack) ring.waitIdle();
      if (takeShot) {
        saveImage(o.screenshot, readSwapchainImage(shot, swapchain.format(), e), {o.force ? Replace::Yes : Replace::No, true});
        std::printf("%s\n", std::filesystem::absolute(o.screenshot).c_str());
        glfwSetWindowShouldClose(window, GLFW_TRUE);
      }
      if (captureRaster) {  // traced on the CPU's cores while frames go on; shown when done
        trace::TraceSettings ts = traceSettings();
        ts.shading = trace::Shading::Pbr;
        ts.shadows = false;
        ts.bounces = 0;
        ts.lens.orthographic = false;
        traced.start(ts, readSwapchainImage(shot, swapchain.format(), e));
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
        for (const auto& [name, ms] : renderer.gpuTimes((f.index + 1) % ring.size())) {
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
    ring.waitIdle();
  }
  return 0;
}

}  // namespace rtr::view
