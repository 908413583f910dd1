// rtr-frame-compare: the whole frame both ways — GPU raster time against CPU trace time, beside the image
// error between them — for the reference cases of tests/reference/poses.txt at a real image size. The
// shading model is the reference tests' (PBR, no shadows, no reflections); docs/reference-tests.md.
#include <cstdio>
#include <filesystem>
#include <thread>

#include <CLI/CLI.hpp>

#include "core/compare.hpp"
#include "core/error.hpp"
#include "reference_common.hpp"

using namespace rtr;
using namespace rtr::reftest;

int main(int argc, char** argv) {
  CLI::App app{"GPU raster vs CPU trace of the reference cases: time and image error"};
  std::string size = "1920x1080", out, device;
  std::vector<std::string> cases;
  int frames = 50;
  unsigned threads = 0;
  app.add_option("--size", size, "image size WxH");
  app.add_option("--frames", frames, "timed GPU frames per case (median)")->check(CLI::Range(1, 10000));
  app.add_option("--threads", threads, "tracer threads, 0 = every core");
  app.add_option("--case", cases, "cases of poses.txt (default: all)");
  app.add_option("--out", out, "folder for <case>_gpu.png, _cpu.png, _err.png");
  app.add_option("--device", device, "Vulkan device index or name substring");
  CLI11_PARSE(app, argc, argv);
  try {
    uint32_t w = 0, h = 0;
    if (std::sscanf(size.c_str(), "%ux%u", &w, &h) != 2 || w == 0 || h == 0)
      throw Error("--size: expected WxH, got '" + size + "'");
    if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
    vk::ContextOptions co = vk::optionsFromEnvironment();
    if (!device.empty()) co.device = device;
    const vk::Context ctx(co);
    const auto poses = loadPoses(posesFile());
    if (cases.empty())
      for (const auto& [name, pose] : poses) cases.push_back(name);
    const std::filesystem::path work =
        out.empty() ? std::filesystem::temp_directory_path() / "rtr-frame-compare" : std::filesystem::path(out);
    std::filesystem::create_directories(work);
    const Limits lim = limits(View::Shaded);
    std::printf(
        "| case | size | GPU frame ms (median of %d) | CPU trace ms (%u threads) | CPU / GPU | CPU Mrays/s "
        "| mean error | max error | failing %% (> %d steps) |\n|---|---|---:|---:|---:|---:|---:|---:|---:|\n",
        frames, threads, lim.threshold);
    for (const std::string& name : cases) {
      if (!poses.count(name)) throw Error(posesFile().string() + ": no case named '" + name + "'");
      const ReferenceScene rs = makeScene(name, work);
      const CasePair p =
          renderPair(ctx, rs, poses.at(name), View::Shaded, {.width = w, .height = h, .threads = threads, .benchFrames = frames});
      const CompareResult r = compareEdgeTolerant(p.gpu, p.cpu, lim.threshold);
      std::printf("| %s | %ux%u | %.3f | %.1f | %.0f× | %.2f | %.3f | %.0f | %.3f |\n", name.c_str(), w, h, p.gpuMs, p.cpuMs,
                  p.cpuMs / p.gpuMs, double(p.cpuRays) / (p.cpuMs * 1e3), r.meanAbsError, r.maxAbsError,
                  100.0 * r.failingFraction);
      std::fflush(stdout);
      if (!out.empty()) {
        savePng(work / (name + "_gpu.png"), p.gpu);
        savePng(work / (name + "_cpu.png"), p.cpu);
        savePng(work / (name + "_err.png"), r.errorMap);
      }
    }
    std::fprintf(stderr, "rtr-frame-compare: device %s\n", ctx.deviceName().c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rtr-frame-compare: %s\n", e.what());
    return 1;
  }
  return 0;
}
