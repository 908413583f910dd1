#pragma once
// Mip-chain generation for 2D textures, two ways: the vkCmdBlitImage chain (baseline) and (default) a
// compute pass that writes up to 6 levels per dispatch, keeping the intermediate levels in float. It
// filters in linear light with the box rule of src/core/mip_reference.hpp (exact fractional coverage
// for odd sizes), each level from the previous one (MipSource::PreviousLevel), within 1 LSB of that
// float64 reference. See docs/post-and-mips.md.
//
// Layout contract of MipGenerator::record (for every image of a batch):
//   on entry  level 0 is in TRANSFER_DST_OPTIMAL (its upload recorded earlier), other levels UNDEFINED;
//   on exit   every level is in SHADER_READ_ONLY_OPTIMAL, its writes visible to fragment and compute
//             shader reads that follow in the same queue.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <vulkan/vulkan.h>

#include "core/enum_names.hpp"
#include "core/image.hpp"
#include "vk/pipeline.hpp"
#include "vk/resources.hpp"

namespace rtr::render {

// Auto: chosen per image by its size. Small images: a GpuScene computes their chains on the CPU as it
// decodes them (hostMipChain: no pipeline, no GPU pass); MipGenerator, which has no texels, takes compute.
// Large images: the blit chain. The default on a CPU device (docs/startup.md).
enum class MipMode { Blit, Compute, Auto };
constexpr std::array<EnumName<MipMode>, 3> enumNames(MipMode) {
  return {{{MipMode::Compute, "compute"}, {MipMode::Blit, "blit"}, {MipMode::Auto, "auto"}}};
}

// Auto's "small": at most this many texels. The crossover measured on lavapipe (docs/startup.md), warm:
// compute is faster than blit below it, blit faster above; and a process's first blits and compute
// pipelines cost compilation there, which the CPU chains avoid.
constexpr uint64_t kAutoSmallTexels = 128 * 128;
bool autoSmall(MipMode mode, VkExtent2D extent);       // Auto, and an image of at most kAutoSmallTexels
MipMode autoMipMode(MipMode mode, VkExtent2D extent);  // on the GPU: `mode` itself unless Auto

// The whole chain of an 8-bit texture (1 or 4 channels, sRGB as in `format`) on the CPU: the float64 box
// filter of core/mip_reference.hpp, each level from the previous one in double (what the compute path
// approximates within 1 LSB). Level k's bytes start at offsets[k] (16-byte aligned).
struct HostMipChain {
  std::vector<uint8_t> bytes;
  std::vector<VkDeviceSize> offsets;
};
HostMipChain hostMipChain(const TexelData& level0, VkFormat format);

// The version of the chains every MipMode makes (shaders, host chain): part of the texture cache's key, so
// bump it whenever a mode's texels for the same level 0 change.
constexpr uint32_t kMipChainVersion = 1;

uint32_t mipLevelCount(VkExtent2D extent);  // floor(log2(max(w, h))) + 1

// An image description for a texture of `format` (R8G8B8A8_SRGB, R8G8B8A8_UNORM, R8_UNORM) with its full
// mip chain and the usage every MipMode needs (sampled, transfer src/dst, storage). sRGB formats get
// MUTABLE_FORMAT + EXTENDED_USAGE (levels are written through UNORM storage views) and their own view
// drops storage usage.
vk::ImageDesc textureDesc(VkExtent2D extent, VkFormat format, const char* name = nullptr);

// The compute dispatches of one image: source level, levels written, and the shader: `even` when every
// level written halves exactly (mips_even.comp), else the general one for odd sizes (mips.comp).
struct MipDispatch {
  uint32_t srcLevel = 0, levels = 1;
  bool even = false;
  VkExtent2D groups{1, 1};
};
std::vector<MipDispatch> planMipDispatches(VkExtent2D extent);

// What a recorded generation uses; keep it until the command buffer has completed.
struct MipViews {
  std::vector<vk::ImageView> source;   // per image: level 0, sampled
  std::vector<vk::ImageView> storage;  // per image, levels 1..: UNORM-equivalent format, storage usage
  vk::Buffer scratch;                  // float copies of every dispatch's last level, for the next dispatch
};

class MipGenerator {
 public:
  // Builds its compute pipelines on first use, only those some image needs (none for blit chains).
  explicit MipGenerator(const vk::Context& ctx);

  // Records the generation of levels 1.. of every image from its level 0 (see the layout contract above).
  // Batched: step k of every image's dispatch plan is recorded for all images, then ONE global barrier,
  // then step k + 1, so independent images' dispatches overlap on the GPU and a batch of textures costs
  // as many barriers as its longest plan has steps (2 for 1024², 3 for 1000x600), not that many per image.
  // Images may differ in size and format. Blit mode records each image's blit chain in turn; Auto records
  // each image the way autoMipMode chooses, the compute ones batched as above.
  [[nodiscard]] MipViews record(VkCommandBuffer cb, std::span<const vk::Image* const> images,
                                MipMode mode = MipMode::Compute) const;
  // One image: the batch of one.
  [[nodiscard]] MipViews record(VkCommandBuffer cb, const vk::Image& image, MipMode mode = MipMode::Compute) const;

 private:
  void recordBlit(VkCommandBuffer cb, const vk::Image& image) const;
  void recordCompute(VkCommandBuffer cb, std::span<const vk::Image* const> images, MipViews& views) const;
  const vk::Pipeline& pipeline(bool even) const;
  const vk::Context& ctx_;
  mutable std::optional<vk::Pipeline> even_, general_;
};

}  // namespace rtr::render
