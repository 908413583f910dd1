#include "vk/pipeline_cache.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>

#include "core/atomic_file.hpp"
#include "core/input_file.hpp"
#include "core/user_cache.hpp"
#include "vk/check.hpp"

namespace rtr::vk {
namespace {

constexpr char kMagic[8] = {'R', 'T', 'R', 'P', 'S', 'O', '1', '\0'};

// Ours, in front of the driver's bytes: what the file is for, and a checksum so that a damaged file is
// caught here rather than by the driver.
struct FileHeader {
  char magic[8];
  uint32_t vendorID, deviceID, driverVersion, reserved;
  uint8_t uuid[VK_UUID_SIZE];
  uint64_t size;      // of the driver's bytes that follow
  uint64_t checksum;  // FNV-1a over them
};
static_assert(sizeof(FileHeader) == 56);

uint64_t fnv1a(const uint8_t* p, size_t n) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
  return h;
}

FileHeader headerFor(const VkPhysicalDeviceProperties& p) {
  FileHeader h{};
  std::memcpy(h.magic, kMagic, sizeof kMagic);
  h.vendorID = p.vendorID;
  h.deviceID = p.deviceID;
  h.driverVersion = p.driverVersion;
  std::memcpy(h.uuid, p.pipelineCacheUUID, VK_UUID_SIZE);
  return h;
}

void note(const std::string& s) { std::fprintf(stderr, "note: %s\n", s.c_str()); }

// Why `bytes` (a whole file) must not be given to the driver; empty when it may.
std::string whyNot(const std::vector<uint8_t>& bytes, const VkPhysicalDeviceProperties& p) {
  if (bytes.size() < sizeof(FileHeader)) return "shorter than its header";
  FileHeader h;
  std::memcpy(&h, bytes.data(), sizeof h);
  const FileHeader want = headerFor(p);
  if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) return "not an rtr pipeline cache";
  if (h.vendorID != want.vendorID || h.deviceID != want.deviceID || h.driverVersion != want.driverVersion ||
      std::memcmp(h.uuid, want.uuid, VK_UUID_SIZE) != 0)
    return "made by another device or driver";
  if (h.size != bytes.size() - sizeof h) return "truncated or padded";
  const uint8_t* data = bytes.data() + sizeof h;
  if (fnv1a(data, h.size) != h.checksum) return "checksum mismatch";
  // The driver's own header (VkPipelineCacheHeaderVersionOne) must agree too.
  if (h.size < 32) return "driver data shorter than its header";
  uint32_t words[4];
  std::memcpy(words, data, sizeof words);
  if (words[0] < 32 || words[1] != VK_PIPELINE_CACHE_HEADER_VERSION_ONE || words[2] != p.vendorID || words[3] != p.deviceID ||
      std::memcmp(data + 16, p.pipelineCacheUUID, VK_UUID_SIZE) != 0)
    return "driver header does not match this device";
  return {};
}

}  // namespace

std::filesystem::path defaultPipelineCacheDir() { return userCacheDir(); }

PipelineCache::PipelineCache(VkDevice device, const VkPhysicalDeviceProperties& props, std::filesystem::path dir)
    : device_(device), props_(props) {
  std::vector<uint8_t> initial;
  if (!dir.empty()) {
    char name[96];
    int n = std::snprintf(name, sizeof name, "pipelines-%04x-%04x-%08x-", props.vendorID, props.deviceID, props.driverVersion);
    for (uint8_t b : props.pipelineCacheUUID) n += std::snprintf(name + n, sizeof name - n, "%02x", b);
    file_ = dir / (std::string(name) + ".bin");
    std::error_code ec;
    if (std::filesystem::exists(file_, ec)) {
      std::vector<uint8_t> bytes;
      std::string why;
      try {  // our own file, but in the user's folder: a FIFO or a huge file there is ignored, not waited on
        const std::string read = readInputFile(file_, "pipeline cache", uint64_t(1) << 30);
        bytes.assign(read.begin(), read.end());
        why = whyNot(bytes, props);
      } catch (const Error& e) { why = e.what(); }
      if (!why.empty()) note("pipeline cache " + file_.string() + " ignored (" + why + "); it will be rewritten");
      else initial.assign(bytes.begin() + sizeof(FileHeader), bytes.end());
    }
  }
  VkPipelineCacheCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
  ci.initialDataSize = initial.size();
  ci.pInitialData = initial.empty() ? nullptr : initial.data();
  VK_CHECK(vkCreatePipelineCache(device_, &ci, nullptr, &cache_));
  loaded_ = !initial.empty();
  loadedBytes_ = std::move(initial);
}

PipelineCache::~PipelineCache() {
  save();
  vkDestroyPipelineCache(device_, cache_, nullptr);
}

namespace {
thread_local int t_beside = 0;  // BesideThread marks alive on this thread
}

PipelineCache::BesideThread::BesideThread() { ++t_beside; }
PipelineCache::BesideThread::~BesideThread() { --t_beside; }
bool PipelineCache::onBesideThread() { return t_beside > 0; }

void PipelineCache::begin() {
  const std::lock_guard lock(mutex_);
  Account& a = onBesideThread() ? beside_ : main_;
  if (a.active++ == 0) a.busySince = std::chrono::steady_clock::now();
}

void PipelineCache::end(const VkPipelineCreationFeedback* f) {
  const std::lock_guard lock(mutex_);
  Account& a = onBesideThread() ? beside_ : main_;
  if (--a.active == 0)
    a.stats.ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a.busySince).count();
  if (!f) return;
  ++a.stats.created;
  if (f->flags & VK_PIPELINE_CREATION_FEEDBACK_VALID_BIT) {
    ++a.stats.reported;
    if (f->flags & VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT) ++a.stats.cacheHits;
  }
}

PipelineStats PipelineCache::stats() const {
  const std::lock_guard lock(mutex_);
  return main_.stats;
}

PipelineStats PipelineCache::besideStats() const {
  const std::lock_guard lock(mutex_);
  return beside_.stats;
}

void PipelineCache::save() {
  if (file_.empty() || !cache_) return;
  const std::lock_guard lock(mutex_);
  size_t size = 0;
  if (vkGetPipelineCacheData(device_, cache_, &size, nullptr) != VK_SUCCESS || size == 0) return;
  std::string bytes(sizeof(FileHeader) + size, '\0');
  auto* data = reinterpret_cast<uint8_t*>(bytes.data()) + sizeof(FileHeader);
  if (vkGetPipelineCacheData(device_, cache_, &size, data) != VK_SUCCESS) return;
  bytes.resize(sizeof(FileHeader) + size);
  if (loadedBytes_.size() == size && std::memcmp(loadedBytes_.data(), data, size) == 0) return;
  FileHeader h = headerFor(props_);
  h.size = size;
  h.checksum = fnv1a(data, size);
  std::memcpy(bytes.data(), &h, sizeof h);
  try {
    std::filesystem::create_directories(file_.parent_path());
    writeFileAtomic(file_, bytes);
    loadedBytes_.assign(data, data + size);
  } catch (const std::exception& e) { note(std::string("pipeline cache not saved: ") + e.what()); }
}

}  // namespace rtr::vk
