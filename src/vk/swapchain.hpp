#pragma once
// Presentation to a surface the app created (the vk library knows no window). FIFO present mode:
// presentation waits for V-sync. Images are UNORM: the post pass encodes sRGB itself, so that compute
// can write them as storage images.
#include <optional>
#include <vector>

#include <vulkan/vulkan.h>

#include "vk/resources.hpp"

namespace rtr::vk {

class Context;

class Swapchain {
 public:
  Swapchain(const Context& ctx, VkSurfaceKHR surface, VkExtent2D windowExtent);
  ~Swapchain();
  Swapchain(const Swapchain&) = delete;
  Swapchain& operator=(const Swapchain&) = delete;

  // The next image to render into; `acquired` is signalled when it may be written. Out-of-date and resize
  // are handled here: the swapchain is recreated first when the window's size changed, a present said so
  // or markStale() was called (waits for the device to go idle), and recreated after an out-of-date
  // acquire, which returns nothing (skip this frame).
  std::optional<uint32_t> acquire(VkSemaphore acquired, VkExtent2D windowExtent);
  // Presents image i once renderDone(i) has been signalled.
  void present(uint32_t i);
  void markStale() { stale_ = true; }

  VkSwapchainKHR handle() const { return swapchain_; }
  VkFormat format() const { return format_; }
  VkExtent2D extent() const { return extent_; }
  VkImageUsageFlags usage() const { return usage_; }
  VkImage image(uint32_t i) const { return images_[i]; }
  VkImageView view(uint32_t i) const { return views_[i]; }
  // Signalled when image i has been rendered; one per image, so a semaphore is never reused while the
  // presentation engine may still wait on it.
  VkSemaphore renderDone(uint32_t i) const { return renderDone_[i]; }

 private:
  void recreate(VkExtent2D windowExtent);
  void create(VkExtent2D windowExtent, VkSwapchainKHR old);
  void destroyViews();

  const Context& ctx_;
  VkSurfaceKHR surface_;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  VkExtent2D extent_{}, windowExtent_{};
  bool stale_ = false;
  VkImageUsageFlags usage_ = 0;
  std::vector<VkImage> images_;
  std::vector<ImageView> views_;
  std::vector<Semaphore> renderDone_;
};

}  // namespace rtr::vk
