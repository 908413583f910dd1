// rtr-bench-gpu: times mip generation (64 textures, blit and compute), the mosaic post-process
// (compute, graphics, off), the environment's prefiltering passes and 64-bit atomicMin against plain stores
// with GPU timestamps; min / median over --runs submissions after --warmup ones.
// Mips also report the largest difference, in LSB, of any texel of any texture from the float64 reference.
// Prints a Markdown table and "csv," lines. Headless: no window, no validation unless RTR_VALIDATION=1.
#include <algorithm>
#include <cstdio>
#include <numeric>
#include <cstring>
#include <stdexcept>
#include <random>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/gtc/packing.hpp>

#include "bench_atomics.h"
#include "core/mip_reference.hpp"
#include "render/environment_maps.hpp"
#include "render/mips.hpp"
#include "render/post.hpp"
#include "render/raster.hpp"
#include "scene/environment.hpp"
#include "vk/commands.hpp"
#include "vk/context.hpp"

namespace {

using namespace rtr;

struct Row {
  std::string pass, size, mode;
  double minMs = 0, medianMs = 0;
  int runs = 0;
  int maxLsb = -1;          // mips: largest |GPU - reference| over every texel of levels >= 1; -1: not checked
  std::string error = "–";  // the error side: against a reference, or against the other path
};

// Times `record` (between two timestamps) over warmup + runs submissions.
template <class Prepare, class Record>
Row measure(const vk::Context& ctx, int warmup, int runs, Prepare prepare, Record record) {
  vk::GpuTimer timer(ctx, 1);
  std::vector<double> ms;
  for (int i = 0; i < warmup + runs; ++i) {
    std::vector<render::MipViews> keep;  // alive until submitAndWait has waited
    vk::submitAndWait(ctx, [&](VkCommandBuffer cb) {
      timer.reset(cb);
      prepare(cb);
      timer.begin(cb);
      record(cb, keep);
      timer.mark(cb, "pass");
    });
    if (i >= warmup) ms.push_back(timer.results().at(0).second);
  }
  std::sort(ms.begin(), ms.end());
  Row r;
  r.minMs = ms.front();
  r.medianMs = ms.size() % 2 ? ms[ms.size() / 2] : 0.5 * (ms[ms.size() / 2 - 1] + ms[ms.size() / 2]);
  r.runs = runs;
  return r;
}

// batched: one MipGenerator::record call for all textures (the default); otherwise one call per texture
// (each with its own barriers, as before batching) for comparison.
std::vector<Row> benchMips(const vk::Context& ctx, VkExtent2D extent, int count, int warmup, int runs, bool batched) {
  std::vector<vk::Image> textures;
  const size_t bytes = size_t(extent.width) * extent.height * 4;
  vk::Buffer upload(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUse::Upload);
  std::mt19937 rng(42);
  for (size_t i = 0; i < bytes; ++i) static_cast<uint8_t*>(upload.mapped())[i] = uint8_t(rng());
  upload.flush();
  for (int i = 0; i < count; ++i) textures.emplace_back(ctx, render::textureDesc(extent, VK_FORMAT_R8G8B8A8_SRGB));
  std::vector<const vk::Image*> batch;
  for (const auto& t : textures) batch.push_back(&t);
  render::MipGenerator gen(ctx);
  // Upload level 0 of every texture once (same content) and leave each chain complete, SHADER_READ_ONLY.
  vk::submitAndWait(ctx, [&](VkCommandBuffer cb) {
    std::vector<render::MipViews> unused;
    for (auto& t : textures) {
      vk::barrier(cb, {{t.handle(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE,
                        VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE, VK_ACCESS_2_TRANSFER_WRITE_BIT, 0, 1}});
      VkBufferImageCopy c{};
      c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      c.imageExtent = {extent.width, extent.height, 1};
      vkCmdCopyBufferToImage(cb, upload.handle(), t.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &c);
      unused.push_back(gen.record(cb, t, render::MipMode::Blit));
    }
  });
  // Before each timed run: level 0 back to the "just uploaded" layout of the contract (content kept).
  auto prepare = [&](VkCommandBuffer cb) {
    std::vector<vk::ImageBarrier> bs;
    for (auto& t : textures)
      bs.push_back({t.handle(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                    VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_NONE,
                    VK_ACCESS_2_TRANSFER_WRITE_BIT, 0, 1});
    vk::barrier(cb, bs);
  };
  std::vector<Row> rows;
  const std::string size =
      std::to_string(count) + " x " + std::to_string(extent.width) + "x" + std::to_string(extent.height) + " sRGB";
  // Every texture's levels 1.. back to the host after a mode's last run, against the float64 reference.
  const TexelData level0{extent.width,
                         extent.height,
                         4,
                         {static_cast<const uint8_t*>(upload.mapped()), static_cast<const uint8_t*>(upload.mapped()) + bytes}};
  const MipChain ref = buildMipReference(level0, TexelEncoding::Srgb, MipSource::PreviousLevel);
  std::vector<std::vector<uint8_t>> want;
  std::vector<VkDeviceSize> offsets;
  VkDeviceSize perTexture = 0;
  for (uint32_t l = 1; l < ref.levels.size(); ++l) {
    want.push_back(quantizeMipLevel(ref, l));
    offsets.push_back(perTexture);
    perTexture += (want.back().size() + 15) & ~VkDeviceSize(15);
  }
  vk::Buffer readback(ctx, perTexture * count, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback);
  auto maxError = [&] {
    vk::submitAndWait(ctx, [&](VkCommandBuffer cb) {
      std::vector<vk::ImageBarrier> toCopy, back;
      for (auto& t : textures) {
        toCopy.push_back({t.handle(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                          VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE,
                          VK_ACCESS_2_TRANSFER_READ_BIT});
        back.push_back({t.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                        VK_PIPELINE_STAGE_2_COPY_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_NONE, VK_ACCESS_2_NONE});
      }
      vk::barrier(cb, toCopy);
      for (size_t i = 0; i < textures.size(); ++i) {
        std::vector<VkBufferImageCopy> copies;
        for (uint32_t l = 1; l < ref.levels.size(); ++l) {
          VkBufferImageCopy c{};
          c.bufferOffset = i * perTexture + offsets[l - 1];
          c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, l, 0, 1};
          c.imageExtent = {ref.levels[l].width, ref.levels[l].height, 1};
          copies.push_back(c);
        }
        vkCmdCopyImageToBuffer(cb, textures[i].handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.handle(),
                               uint32_t(copies.size()), copies.data());
      }
      vk::barrier(cb, back);
      vk::bufferBarrier(cb, vk::kCopyWrite, vk::kHostRead);
    });
    readback.invalidate();
    int worst = 0;
    double sum = 0, count = 0;
    for (size_t i = 0; i < textures.size(); ++i)
      for (size_t l = 0; l < want.size(); ++l) {
        const uint8_t* got = static_cast<const uint8_t*>(readback.mapped()) + i * perTexture + offsets[l];
        for (size_t b = 0; b < want[l].size(); ++b) {
          const int e = std::abs(int(got[b]) - int(want[l][b]));
          worst = std::max(worst, e);
          sum += e;
        }
        count += double(want[l].size());
      }
    return std::pair{worst, sum / count};
  };
  for (render::MipMode mode : {render::MipMode::Blit, render::MipMode::Compute}) {
    Row r = measure(ctx, warmup, runs, prepare, [&](VkCommandBuffer cb, std::vector<render::MipViews>& keep) {
      if (batched) keep.push_back(gen.record(cb, batch, mode));
      else
        for (auto& t : textures) keep.push_back(gen.record(cb, t, mode));
    });
    r.pass = "mips";
    r.size = size;
    r.mode = std::string(enumName(mode)) + (batched ? "" : " (per texture)");
    const auto [worst, mean] = maxError();
    r.maxLsb = worst;
    char err[96];
    std::snprintf(err, sizeof err, "max %d, mean %.4f LSB vs the float64 reference (every texel)", worst, mean);
    r.error = err;
    rows.push_back(r);
    std::fprintf(stderr, "  %s %s: median %.3f ms, max error %d LSB\n", size.c_str(), r.mode.c_str(), r.medianMs, r.maxLsb);
  }
  return rows;
}

std::vector<Row> benchMosaic(const vk::Context& ctx, VkExtent2D extent, int warmup, int runs) {
  vk::Image input(ctx, {extent, VK_FORMAT_R16G16B16A16_SFLOAT, 1, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT});
  vk::Image output(ctx, {extent, VK_FORMAT_R8G8B8A8_UNORM, 1,
                         VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
  const size_t texels = size_t(extent.width) * extent.height * 4;
  vk::Buffer upload(ctx, texels * 2, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUse::Upload);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  auto* h = static_cast<uint16_t*>(upload.mapped());
  for (size_t i = 0; i < texels; ++i) h[i] = glm::packHalf1x16(u(rng));
  upload.flush();
  vk::submitAndWait(ctx, [&](VkCommandBuffer cb) {
    vk::require(cb, input.tracked(), vk::Use::CopyDst, VK_PIPELINE_STAGE_2_COPY_BIT, true);
    VkBufferImageCopy c{};
    c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    c.imageExtent = {extent.width, extent.height, 1};
    vkCmdCopyBufferToImage(cb, upload.handle(), input.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &c);
  });
  render::MosaicPass pass(ctx);
  std::vector<Row> rows;
  // The output of each path, read back after its timed runs: compute and graphics must be identical.
  vk::Buffer readback(ctx, texels, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback);
  auto readOutput = [&] {
    vk::submitAndWait(ctx, [&](VkCommandBuffer cb) {
      vk::require(cb, output.tracked(), vk::Use::CopySrc, VK_PIPELINE_STAGE_2_COPY_BIT);
      vk::copyImageToHost(cb, output.handle(), extent, readback.handle());
    });
    readback.invalidate();
    const auto* p = static_cast<const uint8_t*>(readback.mapped());
    return std::vector<uint8_t>(p, p + texels);
  };
  std::vector<uint8_t> computeBytes;
  const std::string size = std::to_string(extent.width) + "x" + std::to_string(extent.height);
  for (render::MosaicMode mode : {render::MosaicMode::Compute, render::MosaicMode::Graphics, render::MosaicMode::Off}) {
    Row r = measure(
        ctx, warmup, runs, [](VkCommandBuffer) {},
        [&](VkCommandBuffer cb, std::vector<render::MipViews>&) {
          // The pass alone: the layout change for the read-back is made after the timed runs (with it inside,
          // each run paid that layout change too).
          pass.record(cb, input.tracked(), input.view(), output.tracked(), output.view(), VK_FORMAT_R8G8B8A8_UNORM, extent, mode);
        });
    r.pass = "mosaic 5x3";
    r.size = size;
    r.mode = enumName(mode);
    const std::vector<uint8_t> bytes = readOutput();
    if (mode == render::MosaicMode::Compute) {
      computeBytes = bytes;
      r.error = "reference for graphics";
    } else if (mode == render::MosaicMode::Graphics) {
      const auto diff = std::mismatch(bytes.begin(), bytes.end(), computeBytes.begin());
      const size_t at = size_t(diff.first - bytes.begin()) / 4;
      r.error = diff.first == bytes.end() ? "bit-identical to compute (" + std::to_string(texels) + " bytes)"
                                          : "DIFFERS from compute at pixel (" + std::to_string(at % extent.width) + ", " +
                                                std::to_string(at / extent.width) + ")";
    } else {
      r.error = "plain copy (no mosaic)";
    }
    rows.push_back(r);
    std::fprintf(stderr, "  mosaic %s %s: median %.3f ms\n", size.c_str(), r.mode.c_str(), r.medianMs);
  }
  return rows;
}

// The environment's prefiltering (render/environment_maps.hpp) of a generated sky of w x h, pass by pass:
// each run builds the maps in one submission with its own timestamps.
std::vector<Row> benchEnvironment(const vk::Context& ctx, VkExtent2D extent, int warmup, int runs) {
  SkySettings sky;
  sky.width = extent.width;
  sky.height = extent.height;
  const Environment env(makeSky(sky), 1.0f, 0.0f);
  std::vector<std::vector<double>> ms;
  std::vector<std::string> names;
  render::EnvironmentMapSettings used;
  for (int i = 0; i < warmup + runs; ++i) {
    const render::EnvironmentMaps maps(ctx, env);
    used = maps.settings();
    if (i < warmup) continue;
    double total = 0.0;
    for (size_t p = 0; p < maps.times().size(); ++p) {
      if (ms.size() <= p) ms.emplace_back(), names.push_back(maps.times()[p].first);
      ms[p].push_back(maps.times()[p].second);
      total += maps.times()[p].second;
    }
    if (ms.size() <= maps.times().size()) ms.emplace_back(), names.push_back("env total");
    ms[maps.times().size()].push_back(total);
  }
  std::vector<Row> rows;
  const std::string size = std::to_string(extent.width) + "x" + std::to_string(extent.height);
  const std::string mode = "cube " + std::to_string(used.sourceSize) + " specular " + std::to_string(used.specularSize) + "x" +
                           std::to_string(used.specularLevels) + " levels " + std::to_string(used.samples) + " samples";
  for (size_t p = 0; p < ms.size(); ++p) {
    std::sort(ms[p].begin(), ms[p].end());
    Row r;
    r.pass = names[p];
    r.size = size;
    r.mode = mode;
    r.minMs = ms[p].front();
    r.medianMs = ms[p][ms[p].size() / 2];
    r.runs = runs;
    r.error = "tests: CPU references (environment_maps_test)";
    rows.push_back(r);
  }
  std::fprintf(stderr, "  environment %s: median total %.3f ms\n", size.c_str(), rows.back().medianMs);
  return rows;
}

// One 64-bit atomicMin (or store) a thread on a buffer of one word per pixel of `extent`, in each pattern of
// bench_atomics.h: the rate the compute rasteriser's per-pixel write can reach. Each case's result is read
// back after its last run and checked word by word against the CPU's (the minimum of each word's writers).
std::vector<Row> benchAtomics(const vk::Context& ctx, VkExtent2D extent, int warmup, int runs) {
  if (!render::ComputeRaster::supported(ctx)) throw std::runtime_error("atomics: the device has no 64-bit buffer atomics");
  const uint32_t words = extent.width * extent.height;
  uint32_t stride = 1000003;  // a prime, so coprime with any size but its multiples
  while (std::gcd(stride, words) != 1) stride += 2;
  const VkDeviceSize bytes = VkDeviceSize(words) * 8;
  vk::Buffer buffer(ctx, bytes,
                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                    vk::MemoryUse::Device, "atomics");
  vk::Buffer readback(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Readback, "atomics read-back");
  const uint32_t groups = (words + 255) / 256, x = std::min(groups, 65535u), y = (groups + x - 1) / x;
  struct Case {
    const char* name;
    uint32_t pattern, contention;
  };
  const Case cases[] = {{"atomicMin, coherent", BENCH_ATOMIC_COHERENT, 1},
                        {"atomicMin, scattered", BENCH_ATOMIC_SCATTERED, 1},
                        {"atomicMin, 4 threads a word", BENCH_ATOMIC_CONTENDED, 4},
                        {"atomicMin, 32 threads a word", BENCH_ATOMIC_CONTENDED, 32},
                        {"store, coherent", BENCH_STORE_COHERENT, 1},
                        {"store, scattered", BENCH_STORE_SCATTERED, 1}};
  const vk::LayoutOptions push{.pushDescriptorSets = {0}};
  std::vector<Row> rows;
  const std::string size =
      std::to_string(extent.width) + "x" + std::to_string(extent.height) + " (" + std::to_string(words) + " words)";
  for (const Case& c : cases) {
    const vk::Pipeline p = vk::makeComputePipeline(ctx, vk::loadShader("bench_atomics.comp"), push, {{0, c.pattern}});
    auto prepare = [&](VkCommandBuffer cb) {  // every word to all ones, outside the timed region
      vk::bufferBarrier(cb, vk::kComputeReadWrite | vk::kCopyRead, vk::kTransferWrite);
      vkCmdFillBuffer(cb, buffer.handle(), 0, VK_WHOLE_SIZE, ~0u);
      vk::bufferBarrier(cb, vk::kTransferWrite, vk::kComputeReadWrite);
    };
    Row r = measure(ctx, warmup, runs, prepare, [&](VkCommandBuffer cb, std::vector<render::MipViews>&) {
      p.bind(cb);
      vk::DescriptorWriter(ctx, p.layout, 0, VK_NULL_HANDLE).buffer(0, buffer.handle()).push(cb, p);
      p.push(cb, shader::BenchAtomicsPush{words, stride, c.contention, 0});
      vkCmdDispatch(cb, x, y, 1);
    });
    vk::submitAndWait(ctx, [&](VkCommandBuffer cb) {
      vk::bufferBarrier(cb, vk::kComputeReadWrite, vk::kCopyRead);
      const VkBufferCopy all{0, 0, bytes};
      vkCmdCopyBuffer(cb, buffer.handle(), readback.handle(), 1, &all);
      vk::bufferBarrier(cb, vk::kCopyWrite, vk::kHostRead);
    });
    readback.invalidate();
    std::vector<uint64_t> want(words, ~uint64_t(0));
    for (uint32_t i = 0; i < words; ++i) {
      uint32_t w = i;
      if (c.pattern == BENCH_ATOMIC_SCATTERED || c.pattern == BENCH_STORE_SCATTERED) w = uint32_t(uint64_t(i) * stride % words);
      if (c.pattern == BENCH_ATOMIC_CONTENDED) w = i / c.contention;
      want[w] = std::min(want[w], uint64_t(shader::benchAtomicsKey(i)) << 32 | i);
    }
    const auto* got = static_cast<const uint64_t*>(readback.mapped());
    const auto bad = std::mismatch(want.begin(), want.end(), got);
    if (bad.first != want.end())
      throw std::runtime_error(std::string("atomics: ") + c.name + ": word " + std::to_string(bad.first - want.begin()) +
                               " is not its writers' minimum");
    r.pass = "atomics";
    r.size = size;
    r.mode = c.name;
    char note[128];
    std::snprintf(note, sizeof note, "%.3g G ops/s (median), every word checked", words / (r.medianMs * 1e6));
    r.error = note;
    rows.push_back(r);
    std::fprintf(stderr, "  atomics %s: median %.3f ms, %s\n", c.name, r.medianMs, note);
  }
  return rows;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("GPU timings of the mip, mosaic and environment passes and of 64-bit atomics");
  int runs = 25, warmup = 3, textures = 64;
  std::string only;
  std::vector<std::string> sizes{"1024x1024", "1000x600"};
  std::string atomicsSize = "3840x2160";
  bool perTexture = false;
  app.add_option("--runs", runs, "timed submissions per case (min / median)")->check(CLI::Range(1, 10000));
  app.add_option("--warmup", warmup, "untimed submissions first")->check(CLI::Range(0, 1000));
  app.add_option("--textures", textures, "textures per mip case")->check(CLI::Range(1, 1024));
  app.add_option("--only", only, "mips, mosaic, env or atomics")->check(CLI::IsMember({"mips", "mosaic", "env", "atomics"}));
  app.add_option("--mip-sizes", sizes, "texture sizes of the mip cases (WxH ...)");
  app.add_option("--atomics-size", atomicsSize, "the atomics cases' buffer: a word per pixel of WxH");
  app.add_flag("--mips-per-texture", perTexture, "one MipGenerator::record call per texture instead of one batch");
  CLI11_PARSE(app, argc, argv);
  try {
    vk::Context ctx(vk::optionsFromEnvironment());
    std::fprintf(stderr, "device: %s (%s)\n", ctx.deviceName().c_str(), ctx.driverInfo().c_str());
    std::vector<Row> rows;
    auto add = [&](std::vector<Row> r) { rows.insert(rows.end(), r.begin(), r.end()); };
    if (only.empty() || only == "mips") {
      for (const std::string& s : sizes) {
        unsigned w = 0, h = 0;
        if (std::sscanf(s.c_str(), "%ux%u", &w, &h) != 2 || !w || !h)
          throw std::runtime_error("--mip-sizes " + s + ": expected WxH");
        add(benchMips(ctx, {w, h}, textures, warmup, runs, !perTexture));
      }
    }
    if (only.empty() || only == "mosaic") {
      add(benchMosaic(ctx, {1920, 1080}, warmup, runs));
      add(benchMosaic(ctx, {3840, 2160}, warmup, runs));
    }
    if (only.empty() || only == "env") add(benchEnvironment(ctx, {2048, 1024}, std::min(warmup, 1), std::min(runs, 10)));
    // Without 64-bit buffer atomics only an explicit --only atomics fails (benchAtomics says why).
    if (only == "atomics" || (only.empty() && render::ComputeRaster::supported(ctx))) {
      unsigned w = 0, h = 0;
      if (std::sscanf(atomicsSize.c_str(), "%ux%u", &w, &h) != 2 || !w || !h || uint64_t(w) * h >= (1ull << 28))
        throw std::runtime_error("--atomics-size " + atomicsSize + ": expected WxH, under 2^28 pixels");
      add(benchAtomics(ctx, {w, h}, warmup, runs));
    }
    std::printf("Device: %s (%s)\n\n", ctx.deviceName().c_str(), ctx.driverInfo().c_str());
    std::printf("| pass | size | mode | min ms | median ms | runs | error |\n|---|---|---|---:|---:|---:|---|\n");
    for (const Row& r : rows)
      std::printf("| %s | %s | %s | %.3f | %.3f | %d | %s |\n", r.pass.c_str(), r.size.c_str(), r.mode.c_str(), r.minMs,
                  r.medianMs, r.runs, r.error.c_str());
    std::printf("\n");
    for (const Row& r : rows)
      std::printf("csv,%s,%s,%s,%.4f,%.4f,%d,%d\n", r.pass.c_str(), r.size.c_str(), r.mode.c_str(), r.minMs, r.medianMs, r.runs,
                  r.maxLsb);
    if (const uint32_t n = vk::Context::validationMessageCount()) {  // with RTR_VALIDATION=1 (its test)
      std::fprintf(stderr, "rtr-bench-gpu: %u validation messages\n", n);
      return 1;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rtr-bench-gpu: %s\n", e.what());
    return 1;
  }
  return 0;
}
