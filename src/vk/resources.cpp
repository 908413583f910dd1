#include "vk/resources.hpp"

#include <vk_mem_alloc.h>

#include <cstdint>
#include <string>

#include "vk/check.hpp"
#include "vk/context.hpp"

namespace rtr::vk {
namespace {

std::string mb(VkDeviceSize bytes) { return std::to_string((bytes + (1 << 20) - 1) >> 20) + " MB"; }

// Allocation failures become OutOfMemory naming the object and its size; other failures stay VK_CHECK's.
void checkAllocation(VkResult r, const char* call, const char* kind, const char* name, VkDeviceSize bytes) {
  if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY || r == VK_ERROR_MEMORY_MAP_FAILED)
    throw OutOfMemory(std::string(kind) + " '" + (name ? name : "unnamed") + "' needs " + mb(bytes) + ": " + resultName(r));
  if (r < 0) throw Error(std::string(call) + " failed: " + resultName(r));
}

// A mapping that "succeeded" with an address no mapping has (lavapipe out of address space gave
// 0xffffffffffffffff, MAP_FAILED) is a failed one.
bool badMapping(const void* p) { return p == reinterpret_cast<const void*>(~uintptr_t(0)); }

}  // namespace

Buffer::Buffer(const Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use, const char* name)
    : allocator_(ctx.allocator()), size_(size) {
  VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bi.size = size;
  bi.usage = usage;
  VmaAllocationCreateInfo ai{};
  ai.usage = VMA_MEMORY_USAGE_AUTO;
  if (use == MemoryUse::Upload)
    ai.flags = VMA_ALLOCATION_CREATE_HOST_ACCESS_SEQUENTIAL_WRITE_BIT | VMA_ALLOCATION_CREATE_MAPPED_BIT;
  if (use == MemoryUse::Readback) ai.flags = VMA_ALLOCATION_CREATE_HOST_ACCESS_RANDOM_BIT | VMA_ALLOCATION_CREATE_MAPPED_BIT;
  if (use == MemoryUse::DeviceWrite) {
    ai.flags = VMA_ALLOCATION_CREATE_HOST_ACCESS_SEQUENTIAL_WRITE_BIT | VMA_ALLOCATION_CREATE_MAPPED_BIT |
               VMA_ALLOCATION_CREATE_HOST_ACCESS_ALLOW_TRANSFER_INSTEAD_BIT;
    ai.requiredFlags = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
  }
  VmaAllocationInfo info{};
  checkAllocation(vmaCreateBuffer(allocator_, &bi, &ai, &buffer_, &allocation_, &info), "vmaCreateBuffer", "buffer", name, size);
  mapped_ = info.pMappedData;
  const bool mustMap = use == MemoryUse::Upload || use == MemoryUse::Readback;
  if (badMapping(mapped_) || (mustMap && !mapped_)) {
    reset();
    throw OutOfMemory(std::string("buffer '") + (name ? name : "unnamed") + "' of " + mb(size) + " cannot be mapped");
  }
  if (name) ctx.setName(uint64_t(buffer_), VK_OBJECT_TYPE_BUFFER, name);
}

Buffer& Buffer::operator=(Buffer&& o) noexcept {
  if (this != &o) {
    reset();
    allocator_ = o.allocator_;
    buffer_ = std::exchange(o.buffer_, VK_NULL_HANDLE);
    allocation_ = std::exchange(o.allocation_, nullptr);
    size_ = o.size_;
    mapped_ = std::exchange(o.mapped_, nullptr);
  }
  return *this;
}

void Buffer::reset() {
  if (buffer_) vmaDestroyBuffer(allocator_, buffer_, allocation_);
  buffer_ = VK_NULL_HANDLE;
  allocation_ = nullptr;
  mapped_ = nullptr;
}

void Buffer::flush() const { vmaFlushAllocation(allocator_, allocation_, 0, VK_WHOLE_SIZE); }
void Buffer::invalidate() const { vmaInvalidateAllocation(allocator_, allocation_, 0, VK_WHOLE_SIZE); }

bool isDepthFormat(VkFormat f) {
  return f == VK_FORMAT_D32_SFLOAT || f == VK_FORMAT_D16_UNORM || f == VK_FORMAT_D24_UNORM_S8_UINT ||
         f == VK_FORMAT_D32_SFLOAT_S8_UINT;
}

Image::Image(const Context& ctx, const ImageDesc& desc) : device_(ctx.device()), allocator_(ctx.allocator()), desc_(desc) {
  VkImageCreateInfo ii{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ii.flags = desc.flags | (desc.cube ? VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT : 0u);
  ii.imageType = VK_IMAGE_TYPE_2D;
  ii.format = desc.format;
  ii.extent = {desc.extent.width, desc.extent.height, 1};
  ii.mipLevels = desc.mipLevels;
  ii.arrayLayers = desc.cube ? 6 : 1;
  ii.samples = VK_SAMPLE_COUNT_1_BIT;
  ii.tiling = VK_IMAGE_TILING_OPTIMAL;
  ii.usage = desc.usage;
  ii.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VmaAllocationCreateInfo ai{};
  ai.usage = VMA_MEMORY_USAGE_AUTO_PREFER_DEVICE;
  VmaAllocationInfo info{};
  checkAllocation(vmaCreateImage(allocator_, &ii, &ai, &image_, &allocation_, &info), "vmaCreateImage", "image", desc.name,
                  info.size ? info.size : VkDeviceSize(desc.extent.width) * desc.extent.height * 4);
  if (desc.name) ctx.setName(uint64_t(image_), VK_OBJECT_TYPE_IMAGE, desc.name);
  // A copy-only image has no view (Vulkan allows none for such usage).
  constexpr VkImageUsageFlags kViewUsage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
                                           VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
  if (desc.usage & kViewUsage) view_ = createView(desc.format, 0, desc.mipLevels, desc.viewUsage ? desc.viewUsage : desc.usage);
}

ImageView Image::createView(VkFormat format, uint32_t baseMip, uint32_t mipCount, VkImageUsageFlags usage, bool faces) const {
  VkImageViewUsageCreateInfo ui{VK_STRUCTURE_TYPE_IMAGE_VIEW_USAGE_CREATE_INFO};
  ui.usage = usage;
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO, &ui};
  vi.image = image_;
  vi.viewType = !desc_.cube ? VK_IMAGE_VIEW_TYPE_2D : faces ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_CUBE;
  vi.format = format;
  vi.subresourceRange = {VkImageAspectFlags(isDepthFormat(format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT),
                         baseMip, mipCount, 0, desc_.cube ? 6u : 1u};
  VkImageView view;
  VK_CHECK(vkCreateImageView(device_, &vi, nullptr, &view));
  return ImageView(device_, view);
}

Image& Image::operator=(Image&& o) noexcept {
  if (this != &o) {
    reset();
    device_ = o.device_;
    allocator_ = o.allocator_;
    image_ = std::exchange(o.image_, VK_NULL_HANDLE);
    allocation_ = std::exchange(o.allocation_, nullptr);
    desc_ = o.desc_;
    view_ = std::move(o.view_);
    state_ = std::exchange(o.state_, {});
  }
  return *this;
}

void Image::reset() {
  view_.reset();
  if (image_) vmaDestroyImage(allocator_, image_, allocation_);
  image_ = VK_NULL_HANDLE;
  allocation_ = nullptr;
}

}  // namespace rtr::vk
