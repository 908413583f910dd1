// rtr-bench-upload: what the bus allows for the geometry upload (docs/startup.md, "What the bus allows").
// For --mib bytes from a host array that was touched first, on the first device (or RTR_DEVICE):
//  (a) CPU writes (memcpy, 1 MiB pieces on N threads) into mapped device-local memory (MemoryUse::DeviceWrite,
//      the Direct geometry upload), where the device has some: into one buffer again and again, and into a
//      buffer made for each run (every page touched for the first time, as an upload's are);
//  (b) the same into host staging memory: MemoryUse::Upload (write-combined where the device has it) and
//      ::Readback (cached);
//  (c) GPU copies (vkCmdCopyBuffer) host -> device-local: one copy, N copies of each --chunks size in one
//      submission, and one submission per chunk; on the renderer's queue family and on every transfer-only
//      and compute-only family (a device of the tool's own holding one queue of each): wall clock and, where the
//      family has timestamps, GPU time;
//  ((d), the staging ring on its own, measured issue 29's probe: gone with staging as a choice; (e) keeps its letter.)
//  (e) with --scene FILE: the scene's real upload (render::GpuScene, Direct and Staged, alternating; the
//      other phases of its construction aside): the geometry's bytes, time and GB/s, and for Staged where
//      its time went (GpuSceneStats: ring made, slot waits, submits).
// Each case runs --reps times: first (cold), best and median; GB/s from the best (10^9 bytes). The copies'
// bytes are read back and compared (exit 1 on a difference), and any validation message fails the run.
#include <algorithm>
#include <bit>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/error.hpp"
#include "core/parallel.hpp"
#include "render/gpu_scene.hpp"
#include "scene/load.hpp"
#include "vk/check.hpp"
#include "vk/commands.hpp"
#include "vk/context.hpp"
#include "vk/resources.hpp"

using namespace rtr;

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }
constexpr size_t kMiB = size_t(1) << 20;
constexpr size_t kPiece = kMiB;  // what one thread writes at a time (the geometry's pieces are about this size)

// One case's runs: the first (cold), the best, the median; prints a line.
struct Runs {
  std::vector<double> ms;
  void print(const std::string& what, size_t bytes, const std::string& extra = "") const {
    std::vector<double> s = ms;
    std::sort(s.begin(), s.end());
    const double median = s.size() % 2 ? s[s.size() / 2] : 0.5 * (s[s.size() / 2 - 1] + s[s.size() / 2]);
    std::printf("%-92s %6zu MiB  first %8.2f  best %8.2f  median %8.2f ms  %6.2f GB/s%s\n", what.c_str(), bytes / kMiB,
                ms.front(), s.front(), median, double(bytes) / (s.front() * 1e6), extra.c_str());
    std::fflush(stdout);
  }
};

std::string flagNames(VkMemoryPropertyFlags f) {
  std::string s;
  for (auto [bit, name] : {std::pair{VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, "device-local"},
                           {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, "host-visible"},
                           {VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, "coherent"},
                           {VK_MEMORY_PROPERTY_HOST_CACHED_BIT, "cached"}})
    if (f & bit) s += (s.empty() ? "" : "|") + std::string(name);
  return s.empty() ? "-" : s;
}

std::string familyNames(VkQueueFlags f) {
  std::string s;
  for (auto [bit, name] :
       {std::pair{VK_QUEUE_GRAPHICS_BIT, "graphics"}, {VK_QUEUE_COMPUTE_BIT, "compute"}, {VK_QUEUE_TRANSFER_BIT, "transfer"}})
    if (f & bit) s += (s.empty() ? "" : "+") + std::string(name);
  return s.empty() ? "other" : s;
}

// (a), (b): memcpy of `src` into `dst` in 1 MiB pieces on `threads` threads.
void writeAll(uint8_t* dst, const std::vector<uint8_t>& src, unsigned threads) {
  parallelFor((src.size() + kPiece - 1) / kPiece, threads, [&](size_t p) {
    std::memcpy(dst + p * kPiece, src.data() + p * kPiece, std::min(kPiece, src.size() - p * kPiece));
  });
}

void cpuWrites(const vk::Context& ctx, const std::vector<uint8_t>& src, const std::vector<unsigned>& threads, int reps,
               const std::string& only) {
  const std::pair<vk::MemoryUse, const char*> kinds[] = {{vk::MemoryUse::DeviceWrite, "(a) CPU write -> device-local (mapped)"},
                                                         {vk::MemoryUse::Upload, "(b) CPU write -> host Upload"},
                                                         {vk::MemoryUse::Readback, "(b) CPU write -> host Readback"}};
  for (auto [use, name] : kinds) {
    if (only.find(name[1]) == std::string::npos) continue;
    vk::Buffer dst(ctx, src.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, use, name);
    if (!dst.mapped()) {
      std::printf("%-92s (no host-visible device-local memory of this size: skipped)\n", name);
      continue;
    }
    for (unsigned t : threads) {
      Runs r;
      for (int i = 0; i < reps; ++i) {
        const auto t0 = Clock::now();
        writeAll(static_cast<uint8_t*>(dst.mapped()), src, t);
        dst.flush();
        r.ms.push_back(msSince(t0));
      }
      r.print(std::string(name) + ", " + std::to_string(t) + " threads", src.size());
    }
    // As an upload writes it: a buffer made for each run, so that every store touches a fresh page (the
    // making timed apart).
    for (unsigned t : threads) {
      Runs r;
      double made = 0;
      for (int i = 0; i < reps; ++i) {
        auto t0 = Clock::now();
        vk::Buffer fresh(ctx, src.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, use, name);
        made += msSince(t0);
        t0 = Clock::now();
        writeAll(static_cast<uint8_t*>(fresh.mapped()), src, t);
        fresh.flush();
        r.ms.push_back(msSince(t0));
      }
      char extra[64];
      std::snprintf(extra, sizeof extra, "  (buffer made in %.1f ms on average)", made / reps);
      r.print(std::string(name) + ", fresh, " + std::to_string(t) + " threads", src.size(), extra);
    }
  }
}

// (c): a device of the tool's own on the same GPU, with one queue of the renderer's family and of every
// transfer-only and compute-only family, and buffers in raw memory of the chosen types.
class CopyRig {
 public:
  explicit CopyRig(const vk::Context& ctx) : physical_(ctx.physicalDevice()), period_(ctx.timestampPeriodNs()) {
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &n, nullptr);
    families_.resize(n);
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &n, families_.data());
    used_.push_back(ctx.queueFamily());
    for (uint32_t i = 0; i < n; ++i) {
      const VkQueueFlags f = families_[i].queueFlags;
      const bool transferOnly = (f & VK_QUEUE_TRANSFER_BIT) && !(f & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT));
      const bool computeOnly = (f & VK_QUEUE_COMPUTE_BIT) && !(f & VK_QUEUE_GRAPHICS_BIT);
      if (i != ctx.queueFamily() && (transferOnly || computeOnly)) used_.push_back(i);
    }
    const float priority = 1.0f;
    std::vector<VkDeviceQueueCreateInfo> qi;
    for (uint32_t f : used_) {
      VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
      q.queueFamilyIndex = f;
      q.queueCount = 1;
      q.pQueuePriorities = &priority;
      qi.push_back(q);
    }
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    f12.hostQueryReset = VK_TRUE;  // a transfer queue cannot reset queries itself
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f12};
    dci.queueCreateInfoCount = uint32_t(qi.size());
    dci.pQueueCreateInfos = qi.data();
    VK_CHECK(vkCreateDevice(physical_, &dci, nullptr, &device_));
    VkQueryPoolCreateInfo pi{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    pi.queryType = VK_QUERY_TYPE_TIMESTAMP;
    pi.queryCount = 2;
    VK_CHECK(vkCreateQueryPool(device_, &pi, nullptr, &queries_));
  }
  ~CopyRig() {
    for (auto [b, m] : made_) vkDestroyBuffer(device_, b, nullptr), vkFreeMemory(device_, m, nullptr);
    vkDestroyQueryPool(device_, queries_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  CopyRig(const CopyRig&) = delete;
  CopyRig& operator=(const CopyRig&) = delete;

  const std::vector<uint32_t>& families() const { return used_; }
  std::string familyName(uint32_t f) const { return "family " + std::to_string(f) + " " + familyNames(families_[f].queueFlags); }

  // A buffer in the memory type with all of `want`, scored: `prefer` bits present, `avoid` bits absent.
  // Returns the buffer and, where `mapped`, its mapping; `flags` gets the type's properties.
  VkBuffer buffer(size_t bytes, VkMemoryPropertyFlags want, VkMemoryPropertyFlags prefer, VkMemoryPropertyFlags avoid,
                  void** mapped, VkMemoryPropertyFlags* flags) {
    VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bi.size = bytes;
    bi.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    if (used_.size() > 1) {  // read and written by every family measured, without ownership transfers
      bi.sharingMode = VK_SHARING_MODE_CONCURRENT;
      bi.queueFamilyIndexCount = uint32_t(used_.size());
      bi.pQueueFamilyIndices = used_.data();
    }
    VkBuffer b;
    VK_CHECK(vkCreateBuffer(device_, &bi, nullptr, &b));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_, b, &req);
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(physical_, &mp);
    int best = -1, bestScore = -1;
    for (uint32_t i = 0; i < mp.memoryTypeCount; ++i) {
      const VkMemoryPropertyFlags f = mp.memoryTypes[i].propertyFlags;
      if (!(req.memoryTypeBits & (1u << i)) || (f & want) != want) continue;
      const int score = std::popcount(f & prefer) * 2 + std::popcount(~f & avoid);
      if (score > bestScore) best = int(i), bestScore = score;
    }
    if (best < 0) {
      vkDestroyBuffer(device_, b, nullptr);
      throw Error("no memory type for a copy buffer");
    }
    *flags = mp.memoryTypes[best].propertyFlags;
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = uint32_t(best);
    VkDeviceMemory m;
    VK_CHECK(vkAllocateMemory(device_, &ai, nullptr, &m));
    made_.push_back({b, m});
    VK_CHECK(vkBindBufferMemory(device_, b, m, 0));
    if (mapped) VK_CHECK(vkMapMemory(device_, m, 0, VK_WHOLE_SIZE, 0, mapped));
    return b;
  }

  // Runs `record` in one command buffer per entry of `parts` (each submitted on its own, in order) on
  // `family`'s queue; returns the wall time from the first submission to the last one's fence, and the
  // GPU time from the first command buffer's start to the last one's end (-1 without timestamps).
  std::pair<double, double> run(uint32_t family, const std::vector<std::function<void(VkCommandBuffer)>>& parts) {
    VkQueue queue;
    vkGetDeviceQueue(device_, family, 0, &queue);
    VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pi.queueFamilyIndex = family;
    VkCommandPool pool;
    VK_CHECK(vkCreateCommandPool(device_, &pi, nullptr, &pool));
    std::vector<VkCommandBuffer> cbs(parts.size());
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool;
    ai.commandBufferCount = uint32_t(cbs.size());
    VK_CHECK(vkAllocateCommandBuffers(device_, &ai, cbs.data()));
    const bool timed = families_[family].timestampValidBits > 0;
    if (timed) vkResetQueryPool(device_, queries_, 0, 2);
    for (size_t i = 0; i < parts.size(); ++i) {
      VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
      VK_CHECK(vkBeginCommandBuffer(cbs[i], &bi));
      if (timed && i == 0) vkCmdWriteTimestamp(cbs[i], VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries_, 0);
      parts[i](cbs[i]);
      if (timed && i + 1 == parts.size()) vkCmdWriteTimestamp(cbs[i], VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries_, 1);
      VK_CHECK(vkEndCommandBuffer(cbs[i]));
    }
    VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence;
    VK_CHECK(vkCreateFence(device_, &fi, nullptr, &fence));
    const auto t0 = Clock::now();
    for (size_t i = 0; i < cbs.size(); ++i) {
      VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
      si.commandBufferCount = 1;
      si.pCommandBuffers = &cbs[i];
      VK_CHECK(vkQueueSubmit(queue, 1, &si, i + 1 == cbs.size() ? fence : VK_NULL_HANDLE));
    }
    VK_CHECK(vkWaitForFences(device_, 1, &fence, VK_TRUE, UINT64_MAX));
    const double wall = msSince(t0);
    VK_CHECK(vkQueueWaitIdle(queue));
    double gpu = -1;
    uint64_t ts[2];
    if (timed && vkGetQueryPoolResults(device_, queries_, 0, 2, sizeof ts, ts, 8, VK_QUERY_RESULT_64_BIT) == VK_SUCCESS)
      gpu = double(ts[1] - ts[0]) * period_ * 1e-6;
    vkDestroyFence(device_, fence, nullptr);
    vkDestroyCommandPool(device_, pool, nullptr);
    return {wall, gpu};
  }

 private:
  VkPhysicalDevice physical_;
  double period_;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueryPool queries_ = VK_NULL_HANDLE;
  std::vector<VkQueueFamilyProperties> families_;
  std::vector<uint32_t> used_;
  std::vector<std::pair<VkBuffer, VkDeviceMemory>> made_;
};

void gpuCopies(CopyRig& rig, const std::vector<uint8_t>& src, const std::vector<unsigned>& chunksMiB, int reps) {
  const size_t bytes = src.size();
  VkMemoryPropertyFlags devFlags, hostFlags[2];
  const VkBuffer dev =
      rig.buffer(bytes, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, nullptr, &devFlags);
  constexpr VkMemoryPropertyFlags kHost = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  void* at[2];
  // The Upload kind (write-combined, not device-local) and the Readback kind (cached).
  const VkBuffer host[2] = {rig.buffer(bytes, kHost, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_CACHED_BIT,
                                       &at[0], &hostFlags[0]),
                            rig.buffer(bytes, kHost | VK_MEMORY_PROPERTY_HOST_CACHED_BIT, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT,
                                       &at[1], &hostFlags[1])};
  for (int h = 0; h < 2; ++h) std::memcpy(at[h], src.data(), bytes);
  // Each case's result read back (into a cached host buffer) and compared with the source.
  void* backAt = nullptr;
  VkMemoryPropertyFlags backFlags;
  const VkBuffer back = rig.buffer(bytes, kHost, VK_MEMORY_PROPERTY_HOST_CACHED_BIT, 0, &backAt, &backFlags);
  // The target is cleared after each check, so that every case is checked on its own bytes.
  auto check = [&](uint32_t family, const std::string& what) {
    const VkBufferCopy c{0, 0, bytes};
    rig.run(family, {[&](VkCommandBuffer cb) {
              vkCmdCopyBuffer(cb, dev, back, 1, &c);
              VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER, nullptr, VK_ACCESS_TRANSFER_READ_BIT,
                                 VK_ACCESS_TRANSFER_WRITE_BIT};
              vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mb, 0, nullptr, 0,
                                   nullptr);
              vkCmdFillBuffer(cb, dev, 0, VK_WHOLE_SIZE, 0);
            }});
    if (std::memcmp(backAt, src.data(), bytes) != 0) throw Error(what + ": the device's bytes differ from the source");
  };
  std::printf("(c) copy target: %s; sources: %s, %s\n", flagNames(devFlags).c_str(), flagNames(hostFlags[0]).c_str(),
              flagNames(hostFlags[1]).c_str());
  for (uint32_t family : rig.families())
    for (int h = 0; h < 2; ++h) {
      const std::string from =
          std::string("(c) GPU copy ") + (h ? "cached" : "uncached") + " host -> device, " + rig.familyName(family);
      auto measure = [&](const std::string& how, size_t chunk, bool submissions) {
        std::vector<std::function<void(VkCommandBuffer)>> parts;
        std::vector<VkBufferCopy> regions;
        for (size_t b = 0; b < bytes; b += chunk) regions.push_back({b, b, std::min(chunk, bytes - b)});
        if (submissions)
          for (const VkBufferCopy& r : regions)
            parts.push_back([&, r](VkCommandBuffer cb) { vkCmdCopyBuffer(cb, host[h], dev, 1, &r); });
        else
          parts.push_back([&](VkCommandBuffer cb) {
            for (const VkBufferCopy& r : regions) vkCmdCopyBuffer(cb, host[h], dev, 1, &r);
          });
        Runs wall, gpu;
        for (int i = 0; i < reps; ++i) {
          const auto [w, g] = rig.run(family, parts);
          wall.ms.push_back(w), gpu.ms.push_back(g);
        }
        wall.print(from + ", " + how + " (wall)", bytes);
        if (gpu.ms.front() >= 0) gpu.print(from + ", " + how + " (GPU)", bytes);
        check(family, from + ", " + how);
      };
      measure("1 copy", bytes, false);
      for (unsigned c : chunksMiB) {
        const std::string n = std::to_string((bytes + c * kMiB - 1) / (c * kMiB)) + " x " + std::to_string(c) + " MiB";
        measure(n + " copies, 1 submit", c * kMiB, false);
        measure(n + ", 1 submit each", c * kMiB, true);
      }
    }
}

// (e): GpuScene's own upload of `scene` (textures as its defaults load them), the two paths alternating.
void sceneUpload(const vk::Context& ctx, const Scene& scene, const std::string& name, int reps) {
  using render::GeometryUpload;
  Runs runs[2];
  render::GpuSceneStats best[2];
  size_t bytes = 0;
  for (int i = 0; i < reps; ++i)
    for (int p = 0; p < 2; ++p) {
      const render::GpuScene gpu(ctx, scene, render::MipMode::Compute, {}, p ? GeometryUpload::Staged : GeometryUpload::Direct);
      const render::GpuSceneStats& st = gpu.stats();
      runs[p].ms.push_back(st.geometryMs);
      if (st.geometryMs <= *std::min_element(runs[p].ms.begin(), runs[p].ms.end())) best[p] = st;
      bytes = st.geometryBytes;
    }
  for (int p = 0; p < 2; ++p) {
    const render::GpuSceneStats& st = best[p];
    char extra[400];
    int n = std::snprintf(
        extra, sizeof extra, "  (best: plan %.1f, buffers made %.1f, streams + builds %.1f (longest build %.1f), records %.1f ms",
        st.geometryPlanMs, st.geometryBuffersMs, st.geometryStreamsMs, st.geometryLongestBuildMs, st.geometryRecordsMs);
    if (st.geometryCopies)
      n += std::snprintf(extra + n, sizeof extra - n,
                         "; ring made %.1f, slot waits %.1f (threads' sum), submits %.1f ms, %u submits", st.geometryRingMs,
                         st.geometryWaitMs, st.geometrySubmitMs, st.geometryCopies);
    std::snprintf(extra + n, sizeof extra - n, ")");
    // MiB in the line's column; the exact bytes in the name.
    runs[p].print("(e) " + name + " " + std::to_string(bytes) + " B, GpuScene " + (st.geometryCopies ? "staged" : "direct"),
                  bytes, extra);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rtr-bench-upload: CPU writes and GPU copies host to device, and a scene's upload (GB/s)"};
  size_t mib = 1024;
  int reps = 3;
  std::vector<unsigned> threads{1, 2, 4, 8, 16}, chunks{4, 16, 64};
  std::string only = "abc", sceneFile;
  app.add_option("--mib", mib, "bytes to move, in MiB (default 1024)")->check(CLI::Range(1, 65536));
  app.add_option("--reps", reps, "runs per case (default 3): first, best and median are printed")->check(CLI::Range(1, 1000));
  app.add_option("--threads", threads, "(a), (b): thread counts (default 1,2,4,8,16)")
      ->delimiter(',')
      ->check(CLI::Range(1, 1024));
  app.add_option("--chunks", chunks, "(c): copy sizes in MiB besides the one copy (default 4,16,64)")
      ->delimiter(',')
      ->check(CLI::Range(1, 65536));
  app.add_option("--only", only, "which cases: letters of abc (default all; e runs where --scene is given)");
  app.add_option("--scene", sceneFile, "(e): a scene whose GpuScene upload is timed, direct and staged");
  CLI11_PARSE(app, argc, argv);
  try {
    vk::Context ctx(vk::optionsFromEnvironment());
    std::printf("device %s (%s); %u host threads\n", ctx.deviceName().c_str(), ctx.driverInfo().c_str(), threadCount());
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(ctx.physicalDevice(), &mp);
    for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
      std::printf("memory type %u: heap %u (%.1f GiB), %s\n", i, mp.memoryTypes[i].heapIndex,
                  double(mp.memoryHeaps[mp.memoryTypes[i].heapIndex].size) / double(1u << 30),
                  flagNames(mp.memoryTypes[i].propertyFlags).c_str());
    // The source: touched first, so that no page fault is timed; a pattern the copies are checked against.
    std::vector<uint8_t> src(only.find_first_of("abc") == std::string::npos ? 0 : mib * kMiB);
    parallelFor((src.size() + kPiece - 1) / kPiece, 0, [&](size_t p) {
      for (size_t i = p * kPiece; i < std::min(src.size(), (p + 1) * kPiece); ++i) src[i] = uint8_t(i * 2654435761u >> 13);
    });
    if (only.find('a') != std::string::npos || only.find('b') != std::string::npos) cpuWrites(ctx, src, threads, reps, only);
    if (only.find('c') != std::string::npos) {
      CopyRig rig(ctx);
      gpuCopies(rig, src, chunks, reps);
    }
    if (!sceneFile.empty()) {
      src = {};
      const Scene scene = loadScene(sceneFile);
      sceneUpload(ctx, scene, std::filesystem::path(sceneFile).filename().string(), reps);
    }
    if (const uint32_t n = vk::Context::validationMessageCount()) {  // with RTR_VALIDATION=1 (its test)
      std::fprintf(stderr, "rtr-bench-upload: %u validation messages\n", n);
      return 1;
    }
    return 0;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "rtr-bench-upload: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rtr-bench-upload: %s\n", e.what());
    return 1;
  }
}
