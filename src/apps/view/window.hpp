#pragma once
// The viewer's window and its input: GLFW, the Vulkan surface, Dear ImGui's context, and the callbacks
// that turn keys, mouse, scroll and dropped files into ViewState changes.
#include <cstdint>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "view_state.hpp"
#include "vk/context.hpp"

struct GLFWwindow;

namespace rtr::view {

// GLFW for the process: made before the Vulkan instance (which needs its surface extensions), ended last.
struct GlfwSession {
  GlfwSession();
  ~GlfwSession();
  std::vector<const char*> instanceExtensions() const;  // GLFW's strings, valid until the end
};

class Window {
 public:
  // A window of width x height with a surface on ctx's instance; its input changes `state`.
  Window(const vk::Context& ctx, uint32_t width, uint32_t height, ViewState& state);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  VkSurfaceKHR surface() const { return surface_; }
  bool shouldClose() const;
  void close();
  // Takes the pending events. False while minimised (it then waits for the next event): draw nothing.
  bool poll(VkExtent2D& framebuffer);
  void setTitle(const std::string& title);
  // The test-only drop (xdotool cannot drag files): once `file` appears, its lines are read as dropped
  // paths and it is removed.
  void pollDropFile(const std::string& file);

 private:
  const vk::Context& ctx_;
  GLFWwindow* window_ = nullptr;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  std::string imguiIni_;  // Dear ImGui keeps a pointer to it
};

}  // namespace rtr::view
