// GpuScene's textures (render/gpu_scene.hpp): decoded (or, baked and cached chains, taken as they are) on
// all cores, then uploaded batch by batch through one staging ring (render/staging_ring.hpp), their mips
// made on the GPU where no chain came with them; a waited load takes every batch before it returns, a
// deferred one a batch between frames. Docs: docs/startup.md.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <functional>
#include <future>
#include <mutex>

#include "core/error.hpp"
#include "core/image.hpp"
#include "core/parallel.hpp"
#include "render/gpu_scene.hpp"
#include "render/staging_ring.hpp"
#include "scene/baked_texels.hpp"
#include "scene/textures.hpp"
#include "vk/check.hpp"
#include "vk/commands.hpp"
#include "vk/context.hpp"
#include "vk/pipeline_cache.hpp"

namespace rtr::render {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

VkFormat textureFormat(const Texture& t) {
  const bool srgb = decodeSrgb(t);
  if (t.baked && t.baked->format == BakedFormat::Bc1) return srgb ? VK_FORMAT_BC1_RGB_SRGB_BLOCK : VK_FORMAT_BC1_RGB_UNORM_BLOCK;
  if (t.baked && t.baked->format == BakedFormat::Bc3) return srgb ? VK_FORMAT_BC3_SRGB_BLOCK : VK_FORMAT_BC3_UNORM_BLOCK;
  if (t.baked && t.baked->format == BakedFormat::Bc4) return VK_FORMAT_BC4_UNORM_BLOCK;
  if (decodeChannels(t) == 1) return VK_FORMAT_R8_UNORM;
  return srgb ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_R8G8B8A8_UNORM;
}

bool blockCompressed(VkFormat f) { return f >= VK_FORMAT_BC1_RGB_UNORM_BLOCK && f <= VK_FORMAT_BC7_SRGB_BLOCK; }

}  // namespace

// Textures: only those sampled (scene/textures.hpp), decoded on all cores (each thread keeping what it
// decoded until its batch is written into the staging ring); baked chains and the cache's hits are kept as
// they are, to be unpacked straight into the ring. Deferred: on a worker thread while the caller goes on
// (frames render with the materials' factors until updateTextures()). Returns each scene texture's index
// in the GPU's array (NO_TEXTURE: not sampled).
std::vector<uint32_t> GpuScene::startTextures(const Scene& scene, TextureLoad load, std::future<void>& beside) {
  const std::vector<uint32_t> used = sampledTextures(scene);  // scene texture indices, in GPU array order
  std::vector<uint32_t> gpuIndex(scene.textures.size(), NO_TEXTURE);
  for (uint32_t i = 0; i < used.size(); ++i) gpuIndex[used[i]] = i;
  for (uint32_t i : used) formats_.push_back(textureFormat(scene.textures[i])), samplers_.push_back(scene.textures[i].sampler);
  staged_.resize(used.size());
  textures_.resize(used.size());
  hostMips_.assign(used.size(), false);
  in_.assign(used.size(), 0);
  storeKeys_.resize(used.size());
  stats_.textures = uint32_t(used.size());
  VkPhysicalDeviceFeatures features{};
  vkGetPhysicalDeviceFeatures(ctx_.physicalDevice(), &features);
  for (VkFormat f : formats_)
    if (blockCompressed(f) && !features.textureCompressionBC)
      throw Error("this device samples no BC textures (textureCompressionBC); bake the scene with --textures lossless");
  auto decode = [this, &scene, used] {
    const auto t = Clock::now();
    std::mutex progressMutex;
    auto done = [&](uint32_t i) {  // texture i is staged: a deferred load may take it in
      {
        const std::lock_guard lock(decodedMutex_);
        decodedQueue_.push_back(i);
      }
      decodedChanged_.notify_all();
      const std::lock_guard lock(progressMutex);
      const size_t n = ++decoded_;
      if (progress_) progress_("decoding textures", n, staged_.size());
    };
    struct Finished {  // also when the decode throws: a waiting updateTextures() then rethrows
      GpuScene* self;
      ~Finished() {
        {
          const std::lock_guard lock(self->decodedMutex_);
          self->decodeFinished_ = true;
        }
        self->decodedChanged_.notify_all();
      }
    } finished{this};
    // Baked texels (.rtrscene version 6) and the texture cache's hits: staged as they are, whole chains
    // (no decode, no mip pass; their pieces are unpacked into the staging ring with their batch); the
    // others decoded from their images (and, where the cache missed them, stored once their chains are made).
    std::vector<std::shared_ptr<const BakedTexels>> chains(used.size());
    std::vector<TextureCacheKey> keys(used.size());
    std::vector<uint8_t> keyed(used.size(), 0);
    parallelFor(used.size(), 0, [&](size_t i) {
      const Texture& t = scene.textures[used[i]];
      chains[i] = t.baked;
      if (!chains[i] && cache_ && cache_->key(scene, t, cacheVariant_, keys[i]))
        keyed[i] = 1, chains[i] = cache_->find(keys[i], t);
    });
    std::vector<uint32_t> images;
    for (uint32_t i = 0; i < used.size(); ++i) {
      stats_.cacheHits += chains[i] && keyed[i];
      stats_.cacheMisses += !chains[i] && keyed[i];
      if (!chains[i]) {
        images.push_back(i);
        continue;
      }
      Staged& s = staged_[i];
      s.extent = {chains[i]->width, chains[i]->height};
      s.levels = chains[i]->levelOffsets();
      s.bytes = s.levels.back();
      s.levels.pop_back();
      s.chain = std::move(chains[i]);
      done(i);
    }
    stats_.imagesDecoded = uint32_t(images.size());
    std::vector<uint32_t> decodeOnly;
    for (uint32_t i : images) decodeOnly.push_back(used[i]);
    std::vector<uint8_t> fellBack;  // the checker stands in: nothing to store
    decodeTextures(
        scene, decodeOnly,
        [&](size_t j, TexelData&& texels) {
          const uint32_t i = images[j];
          if (keyed[i] && !fellBack[j]) storeKeys_[i] = std::move(keys[i]);
          Staged& s = staged_[i];
          s.extent = {texels.width, texels.height};
          // A small texture under --mips auto: its whole chain, made here (no mip pass on the GPU for it).
          HostMipChain chain;
          if (autoSmall(mipMode_, s.extent)) chain = hostMipChain(texels, formats_[i]);
          s.texels = chain.offsets.empty() ? std::move(texels.texels) : std::move(chain.bytes);
          s.levels = std::move(chain.offsets);
          s.bytes = s.texels.size();
          done(i);
        },
        {}, &fellBack);
    stats_.decodeMs = msSince(t);
  };
  // Waited for: the decode (cache reads, PNG decodes) overlaps the geometry upload, which needs none of it.
  if (load == TextureLoad::Deferred && !used.empty()) decoding_ = std::async(std::launch::async, decode);
  else if (!used.empty())
    beside = std::async(std::launch::async, [this, decode] { decode(), stats_.decodeBesideMs = stats_.decodeMs; });
  else decode();
  return gpuIndex;
}

bool GpuScene::updateTextures(bool wait) {
  if (ready_) return false;
  std::erase_if(materialUpdates_, [](const MaterialUpdate& u) { return u.submission->done(); });
  for (;;) {
    if (upload_) {
      if (!wait && !upload_->submission->done()) return false;
      takeIn();
    }
    if (texturesIn_ == textures_.size()) {
      decoding_.get();  // its statistics are written
      ring_.reset(), fillPool_.reset();
      ready_ = true;
      return true;
    }
    const std::vector<uint32_t> batch = nextBatch(wait);
    if (batch.empty()) return false;
    startUpload(batch);
    if (!wait) return false;
  }
}

size_t GpuScene::batchEnd(const std::vector<uint32_t>& queue, size_t first) const {
  size_t n = first, bytes = 0;
  while (n < queue.size() && (n == first || bytes + staged_[queue[n]].bytes <= uploadBudget_)) bytes += staged_[queue[n++]].bytes;
  return n;
}

// The textures decoded first, up to the budget (at least one); none while none is decoded and not `wait`.
std::vector<uint32_t> GpuScene::nextBatch(bool wait) {
  std::unique_lock lock(decodedMutex_);
  if (wait) decodedChanged_.wait(lock, [&] { return !decodedQueue_.empty() || decodeFinished_; });
  if (decodedQueue_.empty()) {
    if (!decodeFinished_) return {};
    lock.unlock();
    decoding_.get();  // rethrows the decode's error; else every texture was queued
    throw Error("texture streaming: textures missing after the decode");
  }
  const size_t n = batchEnd(decodedQueue_, 0);
  std::vector<uint32_t> batch(decodedQueue_.begin(), decodedQueue_.begin() + n);
  decodedQueue_.erase(decodedQueue_.begin(), decodedQueue_.begin() + n);
  return batch;
}

// A deferred load's batch: upload and mips in one submission, polled by updateTextures() while frames go on.
void GpuScene::startUpload(const std::vector<uint32_t>& batch) {
  for (uint32_t i : batch) createTexture(i);
  if (!mipGen_) mipGen_ = std::make_unique<MipGenerator>(ctx_);
  upload_ = std::make_unique<PendingUpload>(ctx_);
  upload_->batch = batch;
  upload_->start = Clock::now();
  upload_->submission = &submitBatch(batch, [&](VkCommandBuffer cb) {
    upload_->timer.reset(cb);
    upload_->timer.begin(cb);
    upload_->views = mipGen_->record(cb, gpuMipBatch(batch), mipMode_);  // its barriers wait for the copies
    upload_->timer.mark(cb, "mips");
  });
}

// The batch's submission has completed: its chains stored where the cache missed them (read back before any
// frame samples them), then the materials' slots pointed at its textures by a copy that the queue orders
// after the frames submitted so far (they read the old slots) and before the next.
void GpuScene::takeIn() {
  upload_->submission->wait();
  stats_.textureUploadMs += msSince(upload_->start);
  stats_.mipGpuMs += upload_->timer.results().at(0).second;
  const std::vector<uint32_t> batch = std::move(upload_->batch);
  upload_.reset();
  std::vector<std::pair<uint32_t, TextureCacheKey>> misses;
  for (uint32_t i : batch) {
    staged_[i] = {};
    if (storeKeys_[i]) misses.emplace_back(i, std::move(*storeKeys_[i])), storeKeys_[i].reset();
    in_[i] = 1;
  }
  texturesIn_ += batch.size();
  storeInCache(std::move(misses), texturesIn_ == textures_.size());
  for (size_t m = 0; m < shownMaterials_.size(); ++m) {
    auto show = [&](uint32_t& shown, uint32_t full) {
      if (full != NO_TEXTURE && in_[full]) shown = full;
    };
    for (int k = 0; k < 4; ++k) show(shownMaterials_[m].textures[k], texturedMaterials_[m].textures[k]);
    for (int k = 0; k < 3; ++k) show(shownMaterials_[m].textures2[k], texturedMaterials_[m].textures2[k]);
  }
  const size_t bytes = shownMaterials_.size() * sizeof(shader::GpuMaterial);
  MaterialUpdate& u = materialUpdates_.emplace_back();
  u.staging = vk::Buffer(ctx_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUse::Upload, "materials staging");
  std::memcpy(u.staging.mapped(), shownMaterials_.data(), bytes);
  u.staging.flush();
  constexpr vk::BufferUse kReaders = vk::kVertexRead | vk::kFragmentRead | vk::kComputeRead;
  u.submission.emplace(ctx_, [&](VkCommandBuffer cb) {
    vk::bufferBarrier(cb, kReaders, vk::kCopyWrite);  // the frames before read the old slots first
    const VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(cb, u.staging.handle(), materials_.handle(), 1, &region);
    vk::bufferBarrier(cb, vk::kCopyWrite, kReaders);
  });
  ++arrivals_;
}

void GpuScene::createTexture(uint32_t i) {
  vk::ImageDesc desc = textureDesc(staged_[i].extent, formats_[i]);
  if (blockCompressed(formats_[i]))  // baked with its chain: copied into, sampled, nothing else
    desc.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, desc.flags = 0, desc.viewUsage = 0;
  textures_[i] = vk::Image(ctx_, desc);
  hostMips_[i] = !staged_[i].levels.empty();
}

// Every level of each texture the cache missed, copied into a buffer laid out as a baked chain; packed and
// written on a worker thread (the destructor waits for it), then the cache trimmed to its bound.
void GpuScene::storeInCache(std::vector<std::pair<uint32_t, TextureCacheKey>> which, bool last) {
  if (!cache_ || which.empty()) return;
  const auto t = Clock::now();
  struct Back {
    BakedTexels layout;
    vk::Buffer buffer;
    TextureCacheKey key;
  };
  auto backs = std::make_shared<std::vector<Back>>();
  std::vector<vk::ImageBarrier> toSrc, back;
  for (auto& [i, key] : which) {
    Back b;
    b.layout.format = formats_[i] == VK_FORMAT_R8_UNORM ? BakedFormat::R8 : BakedFormat::Rgba8;
    b.layout.width = textures_[i].extent().width;
    b.layout.height = textures_[i].extent().height;
    b.buffer = vk::Buffer(ctx_, b.layout.bytes(), VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback, "cache read-back");
    b.key = std::move(key);
    backs->push_back(std::move(b));
    const uint32_t levels = textures_[i].mipLevels();
    toSrc.push_back({textures_[i].handle(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                     VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                     VK_ACCESS_2_TRANSFER_READ_BIT, 0, levels});
    back.push_back({textures_[i].handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                    VK_PIPELINE_STAGE_2_COPY_BIT,
                    VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_NONE,
                    VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, 0, levels});
  }
  vk::submitAndWait(ctx_, [&](VkCommandBuffer cb) {
    vk::barrier(cb, toSrc);
    for (size_t k = 0; k < backs->size(); ++k) {
      const Back& b = (*backs)[k];
      const std::vector<uint64_t> at = b.layout.levelOffsets();
      std::vector<VkBufferImageCopy> regions;
      for (uint32_t l = 0; l < b.layout.levels(); ++l) {
        VkBufferImageCopy r{};
        r.bufferOffset = at[l];
        r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, l, 0, 1};
        r.imageExtent = {std::max(1u, b.layout.width >> l), std::max(1u, b.layout.height >> l), 1};
        regions.push_back(r);
      }
      vkCmdCopyImageToBuffer(cb, textures_[which[k].first].handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, b.buffer.handle(),
                             uint32_t(regions.size()), regions.data());
    }
    vk::barrier(cb, back);
    vk::bufferBarrier(cb, vk::kCopyWrite, vk::kHostRead);
  });
  stats_.cacheReadbackMs += msSince(t);
  storing_.push_back(std::async(std::launch::async, [cache = cache_, backs, last] {
    parallelFor(backs->size(), 0, [&](size_t k) {
      Back& b = (*backs)[k];
      b.buffer.invalidate();
      const auto* p = static_cast<const uint8_t*>(b.buffer.mapped());
      cache->store(b.key, packBakedTexels(b.layout.format, b.layout.width, b.layout.height,
                                          std::vector<uint8_t>(p, p + b.layout.bytes()), 1));
      b.buffer = {};
    });
    if (last) cache->trim();
  }));
}

const vk::Submission& GpuScene::submitBatch(const std::vector<uint32_t>& batch,
                                            const std::function<void(VkCommandBuffer)>& after) {
  const auto t = Clock::now();
  std::vector<VkDeviceSize> at;
  size_t bytes = 0;
  for (uint32_t i : batch) at.push_back(bytes), bytes = (bytes + staged_[i].bytes + 15) & ~size_t(15);
  if (!ring_) ring_ = std::make_unique<StagingRing>(ctx_, uploadBudget_, 2);
  if (!fillPool_) fillPool_ = std::make_unique<ThreadPool>(threadCount() - 1);
  const uint32_t slot = ring_->acquire(bytes);
  uint8_t* base = ring_->data(slot);
  // Pieces of kBakedPiece bytes: a chain's own (unpacked), or a decoded texture's texels cut the same way.
  std::vector<std::pair<uint32_t, uint32_t>> pieces;  // (batch entry, piece)
  for (uint32_t e = 0; e < batch.size(); ++e) {
    const Staged& s = staged_[batch[e]];
    const size_t n = s.chain ? s.chain->pieces.size() : (s.bytes + kBakedPiece - 1) / kBakedPiece;
    for (uint32_t k = 0; k < n; ++k) pieces.emplace_back(e, k);
  }
  parallelFor(*fillPool_, pieces.size(), [&](size_t p) {
    const auto [e, k] = pieces[p];
    const Staged& s = staged_[batch[e]];
    if (s.chain) return unpackBakedPiece(*s.chain, k, base + at[e]);
    const size_t from = size_t(k) * kBakedPiece;
    std::memcpy(base + at[e] + from, s.texels.data() + from, std::min(kBakedPiece, s.bytes - from));
  });
  for (uint32_t e = 0; e < batch.size(); ++e) {
    at[e] += ring_->offset(slot);
    Staged& s = staged_[batch[e]];
    s.chain.reset(), s.texels = {};  // in the ring now
  }
  fillMs_ += msSince(t);
  ++stats_.uploadBatches;
  const vk::Submission& submission = ring_->submit(slot, [&](VkCommandBuffer cb) {
    recordUpload(cb, batch, at);
    if (after) after(cb);
  });
  stats_.stagingAllocations = ring_->allocations();
  stats_.stagingBytes = ring_->slotBytes() * 2;
  return submission;
}

std::vector<const vk::Image*> GpuScene::gpuMipBatch(const std::vector<uint32_t>& which) const {
  std::vector<const vk::Image*> batch;
  for (uint32_t i : which)
    if (!hostMips_[i]) batch.push_back(&textures_[i]);
  return batch;
}

// Staging memory to level 0 of every texture (every level of those with their chain made on the CPU,
// which are then ready for shaders: the mip generator's layout contract).
void GpuScene::recordUpload(VkCommandBuffer cb, const std::vector<uint32_t>& which, const std::vector<VkDeviceSize>& at) const {
  std::vector<vk::ImageBarrier> toDst, ready;
  for (uint32_t i : which) {
    const uint32_t levels = hostMips_[i] ? textures_[i].mipLevels() : 1;
    toDst.push_back({textures_[i].handle(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                     VK_PIPELINE_STAGE_2_NONE, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE, VK_ACCESS_2_TRANSFER_WRITE_BIT, 0,
                     levels});
    if (hostMips_[i])
      ready.push_back({textures_[i].handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                       VK_PIPELINE_STAGE_2_COPY_BIT,
                       VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                       VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, 0, levels});
  }
  vk::barrier(cb, toDst);
  for (size_t e = 0; e < which.size(); ++e) {
    const uint32_t i = which[e];
    const Staged& st = staged_[i];
    std::vector<VkBufferImageCopy> regions;
    for (uint32_t l = 0; l < (hostMips_[i] ? st.levels.size() : 1); ++l) {
      VkBufferImageCopy r{};
      r.bufferOffset = at[e] + (hostMips_[i] ? st.levels[l] : 0);
      r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, l, 0, 1};
      r.imageExtent = {std::max(1u, st.extent.width >> l), std::max(1u, st.extent.height >> l), 1};
      regions.push_back(r);
    }
    vkCmdCopyBufferToImage(cb, ring_->buffer(), textures_[i].handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                           uint32_t(regions.size()), regions.data());
  }
  if (!ready.empty()) vk::barrier(cb, ready);
}

void GpuScene::finishTextures() {
  const vk::Context& ctx = ctx_;
  vk::PipelineCache& pipelines = ctx.pipelineCache();
  // Texture upload: batch after batch through the staging ring (the writing of one overlaps the copies of
  // the one before). Writing the texels (unpacking chains) is CPU work: it counts as decode.
  auto t = Clock::now();
  std::vector<uint32_t> all(textures_.size());
  for (uint32_t i = 0; i < all.size(); ++i) createTexture(all[i] = i);
  const double fillBefore = fillMs_;
  for (size_t first = 0, end; first < all.size(); first = end) {
    end = batchEnd(all, first);
    submitBatch({all.begin() + first, all.begin() + end}, {});
  }
  ring_.reset(), fillPool_.reset();  // waits for the copies
  staged_.clear();
  stats_.decodeMs += fillMs_ - fillBefore;
  stats_.textureUploadMs = msSince(t) - (fillMs_ - fillBefore);

  // Mips, in a submission of their own (their pipelines' creation is counted as pipeline creation).
  t = Clock::now();
  const double pipelineMs = pipelines.stats().ms;
  if (const std::vector<const vk::Image*> batch = gpuMipBatch(all); !batch.empty()) {
    MipGenerator mipGen(ctx);
    MipViews views;  // alive until the submission has completed
    vk::GpuTimer timer(ctx, 1);
    vk::submitAndWait(ctx, [&](VkCommandBuffer cb) {
      timer.reset(cb);
      timer.begin(cb);
      views = mipGen.record(cb, batch, mipMode_);  // all textures, one barrier per step
      timer.mark(cb, "mips");
    });
    stats_.mipGpuMs = timer.results().at(0).second;
  }
  stats_.mipsMs = msSince(t) - (pipelines.stats().ms - pipelineMs);
}

std::vector<VkImageView> GpuScene::textureViews() const {
  std::vector<VkImageView> out;
  for (size_t i = 0; i < textures_.size(); ++i) out.push_back(in_[i] ? textures_[i].view() : VK_NULL_HANDLE);
  return out;
}

}  // namespace rtr::render
