#include "render/mips.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>

#include "core/error.hpp"
#include "core/mip_reference.hpp"
#include "mips_shared.h"
#include "vk/commands.hpp"
#include "vk/context.hpp"

namespace rtr::render {
namespace {

bool isSrgb(VkFormat f) { return f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_SRGB; }

// The format of the views the compute passes read and write: sRGB images are accessed as UNORM
// (storage sRGB is not generally supported) and the shaders do the transfer functions.
VkFormat unormOf(VkFormat f) {
  if (f == VK_FORMAT_R8G8B8A8_SRGB) return VK_FORMAT_R8G8B8A8_UNORM;
  if (f == VK_FORMAT_B8G8R8A8_SRGB) return VK_FORMAT_B8G8R8A8_UNORM;
  return f;
}

uint32_t levelSize(uint32_t size, uint32_t level) { return std::max(1u, size >> level); }

// Widest range of level-(srcLevel + k) texels any workgroup of a multi-level dispatch needs along one
// axis, for k = 1 .. levels - 1 (the same recursion as mips.comp), against the shared tile sides.
bool axisFits(uint32_t size0, uint32_t levels) {
  std::vector<uint32_t> n(levels + 1);
  n[0] = size0;
  for (uint32_t j = 1; j <= levels; ++j) n[j] = std::max(1u, n[j - 1] >> 1);
  for (uint32_t w = 0; w < n[levels]; ++w) {
    uint64_t lo = w, hi = w + 1;
    for (uint32_t j = levels - 1; j >= 1; --j) {
      lo = lo * n[j] / n[j + 1];
      hi = (hi * n[j] + n[j + 1] - 1) / n[j + 1];
      if (hi - lo > uint64_t(j % 2 ? MIP_CAP_ODD : MIP_CAP_EVEN)) return false;
    }
  }
  return true;
}

}  // namespace

bool autoSmall(MipMode mode, VkExtent2D e) { return mode == MipMode::Auto && uint64_t(e.width) * e.height <= kAutoSmallTexels; }

MipMode autoMipMode(MipMode mode, VkExtent2D e) {
  if (mode != MipMode::Auto) return mode;
  return autoSmall(mode, e) ? MipMode::Compute : MipMode::Blit;
}

namespace {

// One axis of a level from the previous one, the box rule of core/mip_reference.hpp: destination texel x
// covers source [x*W/w, (x+1)*W/w), each source texel weighted by its overlap (at most 3 taps, as w =
// max(1, W >> 1)). Flat arrays: first tap and three weights per destination texel.
struct AxisTaps {
  std::vector<uint32_t> first;
  std::vector<float> weights;  // 3 per destination texel, unused ones 0
};
AxisTaps axisTaps(uint32_t src, uint32_t dst) {
  AxisTaps t{std::vector<uint32_t>(dst), std::vector<float>(size_t(dst) * 3, 0.0f)};
  for (uint64_t x = 0; x < dst; ++x) {
    const uint64_t lo = x * src, hi = (x + 1) * src, i0 = lo / dst, i1 = (hi + dst - 1) / dst;
    t.first[x] = uint32_t(i0);
    for (uint64_t i = i0; i < i1; ++i)
      t.weights[x * 3 + (i - i0)] = float(double(std::min((i + 1) * dst, hi) - std::max(i * dst, lo)) / double(src));
  }
  return t;
}

}  // namespace

HostMipChain hostMipChain(const TexelData& level0, VkFormat format) {
  // Linear light in float (as the compute shaders): sRGB colour channels through a 256-entry table, back
  // through the table of the linear values where each byte's rounding interval starts.
  const uint32_t ch = level0.channels;
  const bool srgb = isSrgb(format) && ch == 4;
  std::array<float, 256> decode{}, start{};  // start[b]: the smallest linear value encoded as b (b >= 1)
  for (int b = 0; b < 256; ++b) {
    decode[b] = float(decodeTexel(uint8_t(b), 0, TexelEncoding::Srgb));
    const double s = (b - 0.5) / 255.0;
    start[b] = float(s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4));
  }
  auto isColour = [&](uint32_t c) { return srgb && c < 3; };
  auto encode = [&](float v, uint32_t c) -> uint8_t {
    v = std::clamp(v, 0.0f, 1.0f);
    if (!isColour(c)) return uint8_t(std::floor(v * 255.0f + 0.5f));
    return uint8_t(std::upper_bound(start.begin() + 1, start.end(), v) - start.begin() - 1);
  };
  uint32_t w = level0.width, h = level0.height;
  std::vector<float> cur(level0.texels.size());
  for (size_t i = 0; i < cur.size(); ++i)
    cur[i] = isColour(uint32_t(i % ch)) ? decode[level0.texels[i]] : float(level0.texels[i]) / 255.0f;
  HostMipChain out;
  out.offsets.push_back(0);
  out.bytes = level0.texels;
  for (uint32_t level = 1; level < mipLevelCount({level0.width, level0.height}); ++level) {
    const uint32_t dw = std::max(1u, w >> 1), dh = std::max(1u, h >> 1);
    const AxisTaps tx = axisTaps(w, dw), ty = axisTaps(h, dh);
    std::vector<float> rows(size_t(h) * dw * ch, 0.0f), next(size_t(dw) * dh * ch, 0.0f);
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < dw; ++x)
        for (uint32_t k = 0; k < 3 && tx.weights[x * 3 + k] > 0; ++k)
          for (uint32_t c = 0; c < ch; ++c)
            rows[(size_t(y) * dw + x) * ch + c] += tx.weights[x * 3 + k] * cur[(size_t(y) * w + tx.first[x] + k) * ch + c];
    for (uint32_t y = 0; y < dh; ++y)
      for (uint32_t k = 0; k < 3 && ty.weights[y * 3 + k] > 0; ++k)
        for (size_t i = 0; i < size_t(dw) * ch; ++i)
          next[size_t(y) * dw * ch + i] += ty.weights[y * 3 + k] * rows[size_t(ty.first[y] + k) * dw * ch + i];
    out.offsets.push_back((out.bytes.size() + 15) & ~size_t(15));
    out.bytes.resize(out.offsets.back() + next.size());
    for (size_t i = 0; i < next.size(); ++i) out.bytes[out.offsets.back() + i] = encode(next[i], uint32_t(i % ch));
    cur = std::move(next);
    w = dw, h = dh;
  }
  return out;
}

uint32_t mipLevelCount(VkExtent2D e) {
  uint32_t m = std::max(e.width, e.height), n = 0;
  while (m) {
    ++n;
    m >>= 1;
  }
  return n;
}

vk::ImageDesc textureDesc(VkExtent2D extent, VkFormat format, const char* name) {
  vk::ImageDesc d;
  d.extent = extent;
  d.format = format;
  d.mipLevels = mipLevelCount(extent);
  d.usage =
      VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_STORAGE_BIT;
  if (isSrgb(format)) {
    d.flags = VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT | VK_IMAGE_CREATE_EXTENDED_USAGE_BIT;
    d.viewUsage = d.usage & ~VK_IMAGE_USAGE_STORAGE_BIT;
  }
  d.name = name;
  return d;
}

std::vector<MipDispatch> planMipDispatches(VkExtent2D extent) {
  std::vector<MipDispatch> plan;
  const uint32_t total = mipLevelCount(extent);
  auto halves = [](uint32_t n) { return n % 2 == 0 || n == 1; };
  for (uint32_t s = 0; s + 1 < total;) {
    MipDispatch d;
    d.srcLevel = s;
    const VkExtent2D src{levelSize(extent.width, s), levelSize(extent.height, s)};
    uint32_t even = 0;
    while (even < MIP_MAX_LEVELS_PER_DISPATCH && s + even + 1 < total && halves(levelSize(extent.width, s + even)) &&
           halves(levelSize(extent.height, s + even)))
      ++even;
    d.even = even > 0;
    if (d.even) {
      d.levels = even;
      d.groups = {(src.width + MIP_EVEN_TILE - 1) / MIP_EVEN_TILE, (src.height + MIP_EVEN_TILE - 1) / MIP_EVEN_TILE};
    } else {
      d.levels = std::min<uint32_t>(MIP_MAX_LEVELS_PER_DISPATCH, total - 1 - s);
      while (d.levels > 1 && !(axisFits(src.width, d.levels) && axisFits(src.height, d.levels))) --d.levels;
      d.groups = {levelSize(extent.width, s + d.levels), levelSize(extent.height, s + d.levels)};
    }
    plan.push_back(d);
    s += d.levels;
  }
  return plan;
}

MipGenerator::MipGenerator(const vk::Context& ctx) : ctx_(ctx) {}

const vk::Pipeline& MipGenerator::pipeline(bool even) const {
  std::optional<vk::Pipeline>& p = even ? even_ : general_;
  if (!p) p = vk::makeComputePipeline(ctx_, vk::loadShader(even ? "mips_even.comp" : "mips.comp"), {.pushDescriptorSets = {0}});
  return *p;
}

void MipGenerator::recordBlit(VkCommandBuffer cb, const vk::Image& image) const {
  const uint32_t n = image.mipLevels();
  const VkImage img = image.handle();
  for (uint32_t i = 1; i < n; ++i) {
    // Level i-1 was just written (upload or previous blit): make it a blit source; level i a destination.
    vk::barrier(cb, {{img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                      VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_PIPELINE_STAGE_2_BLIT_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                      VK_ACCESS_2_TRANSFER_READ_BIT, i - 1, 1},
                     {img, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE,
                      VK_PIPELINE_STAGE_2_BLIT_BIT, VK_ACCESS_2_NONE, VK_ACCESS_2_TRANSFER_WRITE_BIT, i, 1}});
    VkImageBlit b{};
    b.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, i - 1, 0, 1};
    b.srcOffsets[1] = {int32_t(levelSize(image.extent().width, i - 1)), int32_t(levelSize(image.extent().height, i - 1)), 1};
    b.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, i, 0, 1};
    b.dstOffsets[1] = {int32_t(levelSize(image.extent().width, i)), int32_t(levelSize(image.extent().height, i)), 1};
    vkCmdBlitImage(cb, img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &b,
                   VK_FILTER_LINEAR);
  }
  const VkPipelineStageFlags2 readers = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
  std::vector<vk::ImageBarrier> done;
  if (n > 1)  // sources: only reads to wait for (WAR), nothing to make visible
    done.push_back({img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                    VK_PIPELINE_STAGE_2_BLIT_BIT, readers, VK_ACCESS_2_NONE, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, 0, n - 1});
  done.push_back({img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                  VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, readers, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, n - 1, 1});
  vk::barrier(cb, done);
}

MipViews MipGenerator::record(VkCommandBuffer cb, const vk::Image& image, MipMode mode) const {
  const vk::Image* one[] = {&image};
  return record(cb, one, mode);
}

MipViews MipGenerator::record(VkCommandBuffer cb, std::span<const vk::Image* const> images, MipMode mode) const {
  MipViews views;
  std::vector<const vk::Image*> compute;
  for (const vk::Image* image : images) {
    if (autoMipMode(mode, image->extent()) == MipMode::Blit) recordBlit(cb, *image);
    else compute.push_back(image);
  }
  if (!compute.empty()) recordCompute(cb, compute, views);
  return views;
}

void MipGenerator::recordCompute(VkCommandBuffer cb, std::span<const vk::Image* const> images, MipViews& views) const {
  const VkPipelineStageFlags2 readers = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;

  // Per image: its storage views (from `base`), plan, and the scratch offset of each dispatch's last level.
  struct Job {
    const vk::Image* image;
    uint32_t base;
    std::vector<MipDispatch> plan;
    std::vector<VkDeviceSize> region, regionSize;  // per dispatch: where its last level's float copy goes
  };
  const VkDeviceSize align = std::max<VkDeviceSize>(16, ctx_.properties().limits.minStorageBufferOffsetAlignment);
  VkDeviceSize scratchSize = 0;
  std::vector<Job> jobs;
  std::vector<vk::ImageBarrier> start, done;
  size_t steps = 0;
  for (const vk::Image* image : images) {
    const uint32_t n = image->mipLevels();
    const VkImage img = image->handle();
    const VkExtent2D e = image->extent();
    Job job{image, uint32_t(views.storage.size()), planMipDispatches(e), {}, {}};
    const VkFormat unorm = unormOf(image->format());
    // Level 0 through a view of the image's own format: the texture unit decodes sRGB (exactly enough:
    // measured within 1 LSB on lavapipe and the H200, and cheaper than a table or pow in the shader).
    views.source.push_back(image->createView(image->format(), 0, 1, VK_IMAGE_USAGE_SAMPLED_BIT));
    for (uint32_t i = 1; i < n; ++i) views.storage.push_back(image->createView(unorm, i, 1, VK_IMAGE_USAGE_STORAGE_BIT));
    for (const MipDispatch& d : job.plan) {
      const uint32_t last = d.srcLevel + d.levels;
      job.region.push_back(scratchSize);
      job.regionSize.push_back(VkDeviceSize(levelSize(e.width, last)) * levelSize(e.height, last) * 16);
      scratchSize += (job.regionSize.back() + align - 1) / align * align;
    }
    // Level 0 is only read: straight to its final layout. The others are written in GENERAL.
    start.push_back({img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                     VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, readers, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, 0, 1});
    if (n > 1) {
      start.push_back({img, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_NONE,
                       VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_NONE, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, 1, n - 1});
      done.push_back({img, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                      VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, readers, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                      VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, 1, n - 1});
    }
    steps = std::max(steps, job.plan.size());
    jobs.push_back(std::move(job));
  }
  // The shaders the plans use, made in parallel before recording.
  std::vector<std::function<void()>> build;
  for (bool even : {true, false})
    if (std::any_of(jobs.begin(), jobs.end(), [&](const Job& j) {
          return std::any_of(j.plan.begin(), j.plan.end(), [&](const MipDispatch& d) { return d.even == even; });
        }))
      build.push_back([this, even] { pipeline(even); });
  vk::inParallel(build);
  if (scratchSize > 0)
    views.scratch = vk::Buffer(ctx_, scratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUse::Device, "mip scratch");
  if (!start.empty()) vk::barrier(cb, start);

  for (size_t k = 0; k < steps; ++k) {
    // Step k - 1's float copies are step k's sources. One barrier for the whole batch.
    if (k > 0) vk::bufferBarrier(cb, vk::kComputeWrite, vk::kComputeRead);
    const vk::Pipeline* bound = nullptr;
    for (size_t j = 0; j < jobs.size(); ++j) {
      const Job& job = jobs[j];
      if (k >= job.plan.size()) continue;
      const MipDispatch& d = job.plan[k];
      const VkExtent2D extent = job.image->extent();
      const vk::Pipeline& p = pipeline(d.even);
      if (bound != &p) {
        p.bind(cb);
        bound = &p;
      }
      vk::DescriptorWriter w(ctx_, p.layout, 0, VK_NULL_HANDLE);
      w.image(0, views.source[j], VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
      const size_t src = k > 0 ? k - 1 : k;  // the first dispatch reads no scratch, but the binding must be valid
      w.buffer(1, views.scratch.handle(), job.region[src], job.regionSize[src]);
      // Unused slots repeat the last level written, so every descriptor is valid and no extra level is touched.
      std::vector<VkDescriptorImageInfo> outs;
      for (uint32_t l = 1; l <= MIP_MAX_LEVELS_PER_DISPATCH; ++l)
        outs.push_back(
            {VK_NULL_HANDLE, views.storage[job.base + d.srcLevel + std::min(l, d.levels) - 1], VK_IMAGE_LAYOUT_GENERAL});
      w.images(2, outs);
      w.buffer(3, views.scratch.handle(), job.region[k], job.regionSize[k]);
      w.push(cb, p);
      const shader::MipPush push{int(levelSize(extent.width, d.srcLevel)), int(levelSize(extent.height, d.srcLevel)),
                                 int(d.levels), isSrgb(job.image->format()) ? 1 : 0, k > 0 ? 1 : 0};
      p.push(cb, push);
      vkCmdDispatch(cb, d.groups.width, d.groups.height, 1);
    }
  }
  if (!done.empty()) vk::barrier(cb, done);
}

}  // namespace rtr::render
