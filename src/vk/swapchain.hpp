#pragma once
// Presentation to a surface the app created (the vk library knows no window). FIFO present mode:
// presentation waits for V-sync. Images are UNORM: the post pass encodes sRGB itself, so that compute
// can write them as storage images.
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

  // Recreates the swapchain for a new window size (waits for the device to go idle first).
  void recreate(VkExtent2D windowExtent);

  VkSwapchainKHR handle() const { return swapchain_; }
  VkFormat format() const { return format_; }
  VkExtent2D extent() const { return extent_; }
  VkImageUsageFlags usage() const { return usage_; }
  uint32_t imageCount() const { return uint32_t(images_.size()); }
  VkImage image(uint32_t i) const { return images_[i]; }
  VkImageView view(uint32_t i) const { return views_[i]; }
  // Signalled when image i has been rendered; one per image, so a semaphore is never reused while the
  // presentation engine may still wait on it.
  VkSemaphore renderDone(uint32_t i) const { return renderDone_[i]; }

 private:
  void create(VkExtent2D windowExtent, VkSwapchainKHR old);
  void destroyViews();

  const Context& ctx_;
  VkSurfaceKHR surface_;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  VkExtent2D extent_{};
  VkImageUsageFlags usage_ = 0;
  std::vector<VkImage> images_;
  std::vector<ImageView> views_;
  std::vector<Semaphore> renderDone_;
};

}  // namespace rtr::vk
