#include "vk/swapchain.hpp"

#include <algorithm>

#include "vk/check.hpp"
#include "vk/context.hpp"

namespace rtr::vk {

Swapchain::Swapchain(const Context& ctx, VkSurfaceKHR surface, VkExtent2D windowExtent) : ctx_(ctx), surface_(surface) {
  create(windowExtent, VK_NULL_HANDLE);
}

Swapchain::~Swapchain() {
  vkDeviceWaitIdle(ctx_.device());
  destroyViews();
  if (swapchain_) vkDestroySwapchainKHR(ctx_.device(), swapchain_, nullptr);
}

void Swapchain::destroyViews() {
  views_.clear();
  renderDone_.clear();
}

void Swapchain::recreate(VkExtent2D windowExtent) {
  vkDeviceWaitIdle(ctx_.device());
  destroyViews();
  VkSwapchainKHR old = swapchain_;
  create(windowExtent, old);
  vkDestroySwapchainKHR(ctx_.device(), old, nullptr);
}

std::optional<uint32_t> Swapchain::acquire(VkSemaphore acquired, VkExtent2D windowExtent) {
  if (stale_ || windowExtent.width != windowExtent_.width || windowExtent.height != windowExtent_.height) recreate(windowExtent);
  uint32_t i = 0;
  const VkResult r = vkAcquireNextImageKHR(ctx_.device(), swapchain_, UINT64_MAX, acquired, VK_NULL_HANDLE, &i);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) {
    recreate(windowExtent);
    return std::nullopt;
  }
  if (r == VK_SUBOPTIMAL_KHR) stale_ = true;  // usable now; recreated before the next frame
  else VK_CHECK(r);
  return i;
}

void Swapchain::present(uint32_t i) {
  VkSemaphore done = renderDone_[i];
  VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  pi.waitSemaphoreCount = 1;
  pi.pWaitSemaphores = &done;
  pi.swapchainCount = 1;
  pi.pSwapchains = &swapchain_;
  pi.pImageIndices = &i;
  const VkResult r = vkQueuePresentKHR(ctx_.queue(), &pi);
  if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) stale_ = true;
  else VK_CHECK(r);
}

void Swapchain::create(VkExtent2D windowExtent, VkSwapchainKHR old) {
  windowExtent_ = windowExtent;
  stale_ = false;
  VkPhysicalDevice pd = ctx_.physicalDevice();
  VkBool32 presentable = VK_FALSE;
  VK_CHECK(vkGetPhysicalDeviceSurfaceSupportKHR(pd, ctx_.queueFamily(), surface_, &presentable));
  if (!presentable) throw Error("the Vulkan queue cannot present to this window's surface");
  VkSurfaceCapabilitiesKHR caps;
  VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(pd, surface_, &caps));
  uint32_t n = 0;
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(pd, surface_, &n, nullptr));
  std::vector<VkSurfaceFormatKHR> formats(n);
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(pd, surface_, &n, formats.data()));
  VkSurfaceFormatKHR chosen{VK_FORMAT_UNDEFINED, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR};
  for (VkFormat want : {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM})
    for (const auto& f : formats)
      if (chosen.format == VK_FORMAT_UNDEFINED && f.format == want && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR)
        chosen = f;
  if (chosen.format == VK_FORMAT_UNDEFINED) throw Error("the surface offers no 8-bit UNORM sRGB-nonlinear format");
  format_ = chosen.format;

  extent_ = caps.currentExtent.width != UINT32_MAX
                ? caps.currentExtent
                : VkExtent2D{std::clamp(windowExtent.width, caps.minImageExtent.width, caps.maxImageExtent.width),
                             std::clamp(windowExtent.height, caps.minImageExtent.height, caps.maxImageExtent.height)};
  // Storage lets the compute post pass write the image directly; transfer-src serves screenshots,
  // transfer-dst the ray-traced overlay.
  usage_ = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
           (caps.supportedUsageFlags &
            (VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT));
  uint32_t count = std::max(caps.minImageCount + 1, 3u);
  if (caps.maxImageCount) count = std::min(count, caps.maxImageCount);

  VkSwapchainCreateInfoKHR ci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  ci.surface = surface_;
  ci.minImageCount = count;
  ci.imageFormat = chosen.format;
  ci.imageColorSpace = chosen.colorSpace;
  ci.imageExtent = extent_;
  ci.imageArrayLayers = 1;
  ci.imageUsage = usage_;
  ci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ci.preTransform = caps.currentTransform;
  ci.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  ci.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // always supported; waits for V-sync
  ci.clipped = VK_TRUE;
  ci.oldSwapchain = old;
  VK_CHECK(vkCreateSwapchainKHR(ctx_.device(), &ci, nullptr, &swapchain_));

  VK_CHECK(vkGetSwapchainImagesKHR(ctx_.device(), swapchain_, &n, nullptr));
  images_.resize(n);
  VK_CHECK(vkGetSwapchainImagesKHR(ctx_.device(), swapchain_, &n, images_.data()));
  for (VkImage img : images_) {
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = img;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = format_;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkImageView view;
    VK_CHECK(vkCreateImageView(ctx_.device(), &vi, nullptr, &view));
    views_.emplace_back(ctx_.device(), view);
    VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore sem;
    VK_CHECK(vkCreateSemaphore(ctx_.device(), &si, nullptr, &sem));
    renderDone_.emplace_back(ctx_.device(), sem);
  }
}

}  // namespace rtr::vk
