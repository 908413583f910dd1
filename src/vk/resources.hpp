#pragma once
// GPU memory objects owned by value: buffers and images allocated through VMA, released in their
// destructors (move-only), so every object has one owner and a deterministic end.
#include <cstdint>
#include <utility>

#include <vulkan/vulkan.h>

#include "core/error.hpp"
#include "vk/image_state.hpp"

typedef struct VmaAllocation_T* VmaAllocation;
typedef struct VmaAllocator_T* VmaAllocator;

namespace rtr::vk {

class Context;

// A buffer or image the device (or the host, for a CPU device) cannot allocate or map: the message says
// what and how much; callers add the file and the stage ("out of memory while uploading FILE: ...").
struct OutOfMemory : Error {
  using Error::Error;
};

bool isDepthFormat(VkFormat f);

// A device-owned Vulkan handle destroyed with `Destroy` when its owner goes.
template <class T, void (*Destroy)(VkDevice, T, const VkAllocationCallbacks*)>
class Owned {
 public:
  Owned() = default;
  Owned(VkDevice device, T handle) : device_(device), handle_(handle) {}
  Owned(Owned&& o) noexcept : device_(o.device_), handle_(std::exchange(o.handle_, VK_NULL_HANDLE)) {}
  Owned& operator=(Owned&& o) noexcept {
    if (this != &o) {
      reset();
      device_ = o.device_;
      handle_ = std::exchange(o.handle_, VK_NULL_HANDLE);
    }
    return *this;
  }
  ~Owned() { reset(); }
  void reset() {
    if (handle_) Destroy(device_, handle_, nullptr);
    handle_ = VK_NULL_HANDLE;
  }
  T get() const { return handle_; }
  operator T() const { return handle_; }
  explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  T handle_ = VK_NULL_HANDLE;
};

using ImageView = Owned<VkImageView, vkDestroyImageView>;
using Sampler = Owned<VkSampler, vkDestroySampler>;
using Fence = Owned<VkFence, vkDestroyFence>;
using Semaphore = Owned<VkSemaphore, vkDestroySemaphore>;
using CommandPool = Owned<VkCommandPool, vkDestroyCommandPool>;
using QueryPool = Owned<VkQueryPool, vkDestroyQueryPool>;
using DescriptorPool = Owned<VkDescriptorPool, vkDestroyDescriptorPool>;
using DescriptorSetLayout = Owned<VkDescriptorSetLayout, vkDestroyDescriptorSetLayout>;
using PipelineLayoutHandle = Owned<VkPipelineLayout, vkDestroyPipelineLayout>;
using PipelineHandle = Owned<VkPipeline, vkDestroyPipeline>;
using ShaderModuleHandle = Owned<VkShaderModule, vkDestroyShaderModule>;

enum class MemoryUse {
  Device,    // GPU only
  Upload,    // host writes once, sequentially; mapped
  Readback,  // host reads; mapped, cached
  // Device-local, and mapped for sequential writes where the device has host-visible device-local
  // memory (a discrete GPU with a large BAR; every CPU device): mapped() is null where it has not, and
  // the data must go through a staging buffer.
  DeviceWrite,
};

class Buffer {
 public:
  Buffer() = default;
  Buffer(const Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use, const char* name = nullptr);
  Buffer(Buffer&& o) noexcept { *this = std::move(o); }
  Buffer& operator=(Buffer&& o) noexcept;
  ~Buffer() { reset(); }
  void reset();

  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  void* mapped() const { return mapped_; }  // non-null for Upload and Readback (DeviceWrite: see there)
  void flush() const;                       // after host writes
  void invalidate() const;                  // before host reads

 private:
  VmaAllocator allocator_ = nullptr;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VmaAllocation allocation_ = nullptr;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
};

struct ImageDesc {
  VkExtent2D extent{1, 1};
  VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
  uint32_t mipLevels = 1;
  VkImageUsageFlags usage = 0;
  VkImageCreateFlags flags = 0;     // e.g. MUTABLE_FORMAT for a UNORM storage view of an sRGB image
  VkImageUsageFlags viewUsage = 0;  // usage of the default view when narrower than `usage` (0: same)
  const char* name = nullptr;
  bool cube = false;  // six layers, CUBE_COMPATIBLE; the default view is a cube
};

class Image {
 public:
  Image() = default;
  Image(const Context& ctx, const ImageDesc& desc);
  Image(Image&& o) noexcept { *this = std::move(o); }
  Image& operator=(Image&& o) noexcept;
  ~Image() { reset(); }
  void reset();

  VkImage handle() const { return image_; }
  VkImageView view() const { return view_; }  // all mips, the image's own format
  VkFormat format() const { return desc_.format; }
  VkExtent2D extent() const { return desc_.extent; }
  uint32_t mipLevels() const { return desc_.mipLevels; }
  const ImageDesc& desc() const { return desc_; }
  // The image with its tracked state (layout and last access; vk/image_state.hpp), for require().
  TrackedImage tracked() const {
    return {image_, &state_, desc_.name ? desc_.name : "image",
            VkImageAspectFlags(isDepthFormat(desc_.format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT)};
  }

  // A view of a mip range in another (compatible) format with a given usage, owned by the caller. A cube
  // image's views are cubes, or arrays of its six faces (storage writes) where `faces` says so.
  ImageView createView(VkFormat format, uint32_t baseMip, uint32_t mipCount, VkImageUsageFlags usage, bool faces = false) const;

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  VmaAllocator allocator_ = nullptr;
  VkImage image_ = VK_NULL_HANDLE;
  VmaAllocation allocation_ = nullptr;
  ImageDesc desc_{};
  ImageView view_;
  mutable ImageState state_;  // changes as commands are recorded, not the image itself
};

}  // namespace rtr::vk
