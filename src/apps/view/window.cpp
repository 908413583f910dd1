// The viewer's window and input (window.hpp): GLFW callbacks to ViewState, Dear ImGui's context.
#include "window.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>

#include "core/error.hpp"
#include "vk/check.hpp"

namespace rtr::view {
namespace {

ViewState& state(GLFWwindow* w) { return *static_cast<ViewState*>(glfwGetWindowUserPointer(w)); }

void onKey(GLFWwindow* w, int key, int, int action, int) {
  ViewState& app = state(w);
  if (action == GLFW_REPEAT) return;
  const bool down = action == GLFW_PRESS;
  if (down && ImGui::GetIO().WantCaptureKeyboard) return;  // typing into the panel (releases still count)
  switch (key) {                                           // held keys: state from press/release events
    case GLFW_KEY_W: app.camera.setKey(Move::Forward, down); return;
    case GLFW_KEY_S: app.camera.setKey(Move::Back, down); return;
    case GLFW_KEY_A: app.camera.setKey(Move::Left, down); return;
    case GLFW_KEY_D: app.camera.setKey(Move::Right, down); return;
    case GLFW_KEY_E: app.camera.setKey(Move::Up, down); return;
    case GLFW_KEY_Q: app.camera.setKey(Move::Down, down); return;
    case GLFW_KEY_LEFT_SHIFT:
    case GLFW_KEY_RIGHT_SHIFT: app.camera.setKey(Move::Fast, down); return;
    case GLFW_KEY_LEFT_CONTROL:
    case GLFW_KEY_RIGHT_CONTROL: app.camera.setKey(Move::Slow, down); return;
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
  else if (key == GLFW_KEY_LEFT) app.fileStep = -1;
  else if (key == GLFW_KEY_RIGHT) app.fileStep = 1;
  else if (key == GLFW_KEY_F5) app.reloadRequested = true;
  else if (key == GLFW_KEY_C) {
    std::printf("--camera %s\n", formatPose(app.camera.pose()).c_str());
    if (app.camera.mode() == CameraMode::Orbit) {
      const glm::vec3 t = app.camera.orbitTarget();
      std::printf("orbit target %.9g,%.9g,%.9g distance %.9g\n", t.x, t.y, t.z, app.camera.orbitDistance());
    }
    std::fflush(stdout);
  } else if (key == GLFW_KEY_F1 || key == GLFW_KEY_H) app.panel = !app.panel;
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

// Dear ImGui's layout file in the user's config folder; empty when there is none.
std::string imguiIniPath() {
  const char* xdg = std::getenv("XDG_CONFIG_HOME");
  const char* home = std::getenv("HOME");
  if (!(xdg && *xdg) && !(home && *home)) return {};
  const std::filesystem::path dir =
      (xdg && *xdg) ? std::filesystem::path(xdg) / "rtr" : std::filesystem::path(home) / ".config" / "rtr";
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  return ec ? std::string() : (dir / "imgui.ini").string();
}

}  // namespace

GlfwSession::GlfwSession() {
  if (!glfwInit()) throw Error("cannot initialise GLFW (no display? use --headless)");
}
GlfwSession::~GlfwSession() { glfwTerminate(); }

std::vector<const char*> GlfwSession::instanceExtensions() const {
  uint32_t count = 0;
  const char** exts = glfwGetRequiredInstanceExtensions(&count);
  if (!exts) throw Error("GLFW found no Vulkan surface support");
  return {exts, exts + count};
}

Window::Window(const vk::Context& ctx, uint32_t width, uint32_t height, ViewState& app) : ctx_(ctx) {
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  window_ = glfwCreateWindow(int(width), int(height), "rtr-view", nullptr, nullptr);
  if (!window_) throw Error("cannot create a window");
  if (glfwCreateWindowSurface(ctx.instance(), window_, nullptr, &surface_) != VK_SUCCESS) {
    glfwDestroyWindow(window_);
    throw Error("cannot create a Vulkan surface for the window");
  }
  glfwSetWindowUserPointer(window_, &app);
  glfwSetKeyCallback(window_, onKey);
  glfwSetMouseButtonCallback(window_, onMouseButton);
  glfwSetCursorPosCallback(window_, onCursor);
  glfwSetScrollCallback(window_, onScroll);
  glfwSetDropCallback(window_, onDrop);
  glfwSetFramebufferSizeCallback(window_, onResize);

  // Dear ImGui: its layout in the user's config folder, sized by the monitor's content scale.
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  imguiIni_ = imguiIniPath();
  io.IniFilename = imguiIni_.empty() ? nullptr : imguiIni_.c_str();
  float xs = 1, ys = 1;
  glfwGetWindowContentScale(window_, &xs, &ys);
  ImFontConfig font;
  font.SizePixels = 13.0f * std::max(1.0f, xs);
  io.Fonts->AddFontDefault(&font);
  ImGui::GetStyle().ScaleAllSizes(std::max(1.0f, xs));
  ImGui_ImplGlfw_InitForVulkan(window_, true);  // chains to the callbacks installed above
}

Window::~Window() {
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  vkDestroySurfaceKHR(ctx_.instance(), surface_, nullptr);
  glfwDestroyWindow(window_);
}

bool Window::shouldClose() const { return glfwWindowShouldClose(window_); }
void Window::close() { glfwSetWindowShouldClose(window_, GLFW_TRUE); }
void Window::setTitle(const std::string& title) { glfwSetWindowTitle(window_, title.c_str()); }

bool Window::poll(VkExtent2D& framebuffer) {
  glfwPollEvents();
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  // Minimised: pause rendering until restored. A minimised window has a zero framebuffer on Windows
  // only; on X11 it keeps its size, and the iconified state is the window manager's WM_STATE.
  if (w == 0 || h == 0 || glfwGetWindowAttrib(window_, GLFW_ICONIFIED)) {
    glfwWaitEvents();
    return false;
  }
  framebuffer = {uint32_t(w), uint32_t(h)};
  return true;
}

void Window::pollDropFile(const std::string& file) {
  std::error_code ec;
  if (file.empty() || !std::filesystem::exists(file, ec)) return;
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);)
    if (!l.empty()) lines.push_back(l);
  std::filesystem::remove(file, ec);
  std::vector<const char*> paths;
  for (const auto& l : lines) paths.push_back(l.c_str());
  onDrop(window_, int(paths.size()), paths.data());
}

}  // namespace rtr::view
