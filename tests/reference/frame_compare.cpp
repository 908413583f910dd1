// rtr-frame-compare: the whole frame both ways — GPU raster time against CPU trace time, beside the image
// error between them — for the reference cases of tests/reference/poses.txt at a real image size. The
// shading model is the reference tests' (PBR, no shadows, no reflections); docs/reference-tests.md.
// --env-cases: the environment-lit cases instead, the GPU's split sum against the tracer's Monte Carlo at
// --spp sample pairs (docs/environment.md); --spp-curve CASE: the tracer's error against its sample count.
// Every table has the ꟻLIP-style error (core/flip.hpp, docs/flip.md) at --ppd; --flip A.png B.png prints it
// for two images alone (no GPU), with the largest channel difference's statistics.
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <map>
#include <thread>

#include <CLI/CLI.hpp>

#include "core/cli.hpp"
#include "core/compare.hpp"
#include "core/error.hpp"
#include "core/flip.hpp"
#include "reference_common.hpp"

using namespace rtr;
using namespace rtr::reftest;

namespace {

const PoseEntry& poseOf(const std::map<std::string, PoseEntry>& poses, const std::string& name) {
  if (!poses.count(name)) throw Error(posesFile().string() + ": no case named '" + name + "'");
  return poses.at(name);
}

// Linear radiance as the PNG a person looks at; the uncovered marker shows black.
void saveLinear(const std::filesystem::path& file, const ImageF& img) { savePng(file, toSrgb8(img)); }

// The pixels both environment images cover (the other errors' pixels).
std::vector<bool> covered(const ImageF& a, const ImageF& b) {
  std::vector<bool> m(a.pixels.size());
  for (size_t i = 0; i < m.size(); ++i) m[i] = a.pixels[i].r != kUncovered && b.pixels[i].r != kUncovered;
  return m;
}

ImageRGBA8 loadPng(const std::string& file) {
  TexelData t = loadImage(file, 4);
  return ImageRGBA8{t.width, t.height, std::move(t.texels)};
}

// --flip A B: the ꟻLIP-style error of B against A, and the mean over pixels of the largest channel
// difference (0-255), its maximum and the share of pixels off by more than 16 and 64 (the LOD rows).
int flipFiles(const std::string& fileA, const std::string& fileB, double ppd, const std::string& map) {
  const ImageRGBA8 a = loadPng(fileA), b = loadPng(fileB);
  if (a.width != b.width || a.height != b.height)
    throw Error(fileB + " is " + std::to_string(b.width) + "x" + std::to_string(b.height) + ", " + fileA + " is " +
                std::to_string(a.width) + "x" + std::to_string(a.height));
  const FlipResult r = flip(a, b, {.ppd = ppd});
  const FlipStats f = r.stats();
  double sum = 0;
  int worst = 0;
  size_t over16 = 0, over64 = 0;
  for (size_t i = 0; i < size_t(a.width) * a.height; ++i) {
    int d = 0;
    for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a.pixels[4 * i + c]) - int(b.pixels[4 * i + c])));
    sum += d;
    worst = std::max(worst, d);
    over16 += d > 16;
    over64 += d > 64;
  }
  const double n = double(a.width) * a.height;
  std::printf(
      "flip mean %.6f p99 %.4f max %.4f (%.0f ppd); largest channel difference mean %.4f max %d over16 %.3f%% over64 %.3f%%\n",
      f.mean, f.p99, f.max, ppd, sum / n, worst, 100.0 * double(over16) / n, 100.0 * double(over64) / n);
  if (!map.empty()) savePng(map, flipHeatMap(r));
  return 0;
}

int environmentCases(const vk::Context& ctx, const std::map<std::string, PoseEntry>& poses, const std::vector<std::string>& cases,
                     uint32_t w, uint32_t h, unsigned threads, int frames, int spp, double ppd, const std::filesystem::path& work,
                     bool save) {
  std::printf(
      "| case | size | spp | GPU frame ms (median of %d) | GPU prefilter ms | CPU trace s (%u threads) | mean pixel "
      "| mean abs error | %% of mean pixel | mean per-pixel error %% | max abs error | tracer noise per-pixel %% (est.) "
      "| sRGB mean steps | sRGB max steps | ꟻLIP mean | ꟻLIP 99th pct | ꟻLIP max |\n"
      "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
      frames, threads);
  std::string perPart;
  for (const std::string& name : cases) {
    if (!isEnvironmentCase(name)) throw Error("--env-cases: '" + name + "' is not an environment case (env_*)");
    const ReferenceScene rs = makeScene(name, work);
    const PoseEntry& pose = poseOf(poses, name);
    const PairOptions o{.width = w, .height = h, .threads = threads, .benchFrames = frames, .spp = spp};
    const CasePair p = renderPair(ctx, rs, pose, View::Shaded, o);
    // The tracer's own noise at spp: its first spp/4 pairs are a prefix of the spp run's (per-pixel
    // sequences), so I(spp/4) - I(spp) has 3x the variance of I(spp)'s error: noise ~ that / sqrt(3).
    PairOptions quarter = o;
    quarter.spp = spp / 4;
    const ImageF q = traceCase(rs, pose, View::Shaded, quarter);
    const EnvError e = envError(p.gpuLinear, p.cpuLinear), noise = envError(q, p.cpuLinear);
    double prefilter = 0;
    for (const auto& [pass, ms] : p.prefilterMs) prefilter += ms;
    const CompareResult r = compareEdgeTolerant(p.gpu, p.cpu, 3);
    // What a display shows (clamped to [0, 1]), over the pixels both cover, as the other errors.
    const FlipResult fr = flip(p.gpuLinear, p.cpuLinear, {.ppd = ppd, .threads = threads});
    const std::vector<bool> both = covered(p.gpuLinear, p.cpuLinear);
    const FlipStats f = fr.stats(&both);
    std::printf(
        "| %s | %ux%u | %d | %.3f | %.1f | %.1f | %.3f | %.4f | %.1f | %.1f | %.2f | %.1f | %.2f | %.0f | %.4f | %.3f | %.3f |\n",
        name.c_str(), w, h, spp, p.gpuMs, prefilter, p.cpuMs / 1e3, e.meanRef, e.meanAbs, 100.0 * e.relative(),
        100.0 * e.meanPixelRelative, e.maxAbs, 100.0 * noise.meanPixelRelative / std::sqrt(3.0), r.meanAbsError, r.maxAbsError,
        f.mean, f.p99, f.max);
    std::fflush(stdout);
    const std::vector<int> part = partOfPixels(rs, pose, w, h, p.cpuLinear);
    // The split sum evaluated exactly (the spheres have no textures): who is wrong where GPU and tracer differ.
    const ImageF exact = rs.parts.empty() ? ImageF{} : splitSumCase(rs, pose, o);
    for (size_t k = 0; k < rs.parts.size(); ++k) {
      std::vector<bool> mask(part.size());
      for (size_t i = 0; i < part.size(); ++i) mask[i] = part[i] == int(k) && both[i];
      const EnvError pe = envError(p.gpuLinear, p.cpuLinear, &mask), pn = envError(q, p.cpuLinear, &mask);
      const EnvError own = envError(exact, p.cpuLinear, &mask), impl = envError(p.gpuLinear, exact, &mask);
      char line[320];
      std::snprintf(line, sizeof line, "| %s | %s | %zu | %.3f | %.4f | %.1f | %.1f | %.2f | %.1f | %.1f | %.1f | %.4f |\n",
                    name.c_str(), rs.parts[k].name.c_str(), pe.pixels, pe.meanRef, pe.meanAbs, 100.0 * pe.relative(),
                    100.0 * pe.meanPixelRelative, pe.maxAbs, 100.0 * pn.meanPixelRelative / std::sqrt(3.0),
                    100.0 * own.relative(), 100.0 * impl.relative(), fr.stats(&mask).mean);
      perPart += line;
    }
    if (save) {
      saveLinear(work / (name + "_gpu.png"), p.gpuLinear);
      saveLinear(work / (name + "_cpu.png"), p.cpuLinear);
      saveImage(work / (name + "_gpu.exr"), p.gpuLinear);
      saveImage(work / (name + "_cpu.exr"), p.cpuLinear);
      savePng(work / (name + "_err.png"), r.errorMap);
      savePng(work / (name + "_flip.png"), flipHeatMap(fr));
    }
  }
  if (!perPart.empty())
    std::printf(
        "\nPer sphere:\n\n| case | sphere | pixels | mean pixel | mean abs error | %% of mean pixel | mean per-pixel "
        "error %% | max abs error | tracer noise per-pixel %% (est.) | exact split sum vs tracer, %% of mean pixel "
        "| GPU vs exact split sum, %% of mean pixel | ꟻLIP mean |\n"
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n%s",
        perPart.c_str());
  return 0;
}

// The tracer's error against its sample count: spp 1, 4, 16, ... below the reference's count, each
// against the reference (whose own error, at 4x the largest count, adds at most ~1/8 to that one's).
int sppCurve(const std::map<std::string, PoseEntry>& poses, const std::string& name, uint32_t w, uint32_t h, unsigned threads,
             int refSpp, double ppd, const std::filesystem::path& work, bool save) {
  const ReferenceScene rs = makeScene(name, work);
  if (!rs.environment) throw Error("--spp-curve: '" + name + "' is not an environment case (env_*)");
  const PoseEntry& pose = poseOf(poses, name);
  trace::RenderStats st, refStats;
  const ImageF ref = traceCase(rs, pose, View::Shaded, {.width = w, .height = h, .threads = threads, .spp = refSpp}, &refStats);
  std::printf(
      "| case | size | spp | mean abs error | %% of mean pixel | mean per-pixel error %% | RMS error | max abs error "
      "| trace s (%u threads) | ꟻLIP mean |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
      threads);
  for (int spp = 1; spp < refSpp; spp *= 4) {
    const ImageF img = traceCase(rs, pose, View::Shaded, {.width = w, .height = h, .threads = threads, .spp = spp}, &st);
    const EnvError e = envError(img, ref);
    double sq = 0;
    for (size_t i = 0; i < img.pixels.size(); ++i)
      if (img.pixels[i].r != kUncovered && ref.pixels[i].r != kUncovered)
        for (int c = 0; c < 3; ++c) sq += double(img.pixels[i][c] - ref.pixels[i][c]) * (img.pixels[i][c] - ref.pixels[i][c]);
    const std::vector<bool> both = covered(img, ref);
    std::printf("| %s | %ux%u | %d | %.4f | %.2f | %.2f | %.4f | %.3f | %.2f | %.4f |\n", name.c_str(), w, h, spp, e.meanAbs,
                100.0 * e.relative(), 100.0 * e.meanPixelRelative, std::sqrt(sq / (3.0 * double(std::max<size_t>(e.pixels, 1)))),
                e.maxAbs, st.seconds, flip(img, ref, {.ppd = ppd, .threads = threads}).stats(&both).mean);
    std::fflush(stdout);
    if (save) saveLinear(work / (name + "_spp" + std::to_string(spp) + ".png"), img);
  }
  std::printf("\nreference: %d spp (%.1f s)\n", refSpp, refStats.seconds);
  if (save) saveLinear(work / (name + "_spp" + std::to_string(refSpp) + ".png"), ref);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"GPU raster vs CPU trace of the reference cases: time and image error", "rtr-frame-compare"};
  std::string size = "1920x1080", out, device;
  std::vector<std::string> cases;
  int frames = 50;
  unsigned threads = 0;
  app.add_option("--size", size, "image size WxH");
  app.add_option("--frames", frames, "timed GPU frames per case (median)")->check(CLI::Range(1, 10000));
  app.add_option("--threads", threads, "tracer threads, 0 = every core");
  app.add_option("--case", cases, "cases of poses.txt (default: all)");
  app.add_option("--out", out, "folder for <case>_gpu.png, _cpu.png, _err.png, _flip.png (the ꟻLIP-style error map)");
  app.add_option("--device", device, "Vulkan device index or name substring");
  bool envCases = false;
  int spp = 256;
  std::string curve;
  app.add_flag("--env-cases", envCases, "the environment-lit cases (env_*): split sum vs the tracer at --spp");
  app.add_option("--spp", spp, "the tracer's sample pairs a pixel in environment cases")->check(CLI::Range(4, 65536));
  app.add_option("--spp-curve", curve, "an environment case traced at 1, 4, ... spp/4 against --spp: the error curve");
  std::vector<std::string> flipPair;
  std::string flipMap;
  double ppd = 67.0;
  app.add_option("--flip", flipPair, "A.png B.png: the ꟻLIP-style error of B against A alone (no rendering)")->expected(2);
  app.add_option("--flip-map", flipMap, "with --flip: the error map as a heat-map PNG");
  app.add_option("--ppd", ppd, "viewing distance for the ꟻLIP-style error, in pixels per degree")
      ->check(cli::number(1.0, 1000.0));
  if (const int rc = cli::parse(app, argc, argv); rc >= 0) return rc;  // usage errors: exit 2
  try {
    if (!flipPair.empty()) return flipFiles(flipPair[0], flipPair[1], ppd, flipMap);
    uint32_t w = 0, h = 0;
    if (std::sscanf(size.c_str(), "%ux%u", &w, &h) != 2 || w == 0 || h == 0)
      throw Error("--size: expected WxH, got '" + size + "'");
    if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
    vk::ContextOptions co = vk::optionsFromEnvironment();
    if (!device.empty()) co.device = device;
    const vk::Context ctx(co);
    const auto poses = loadPoses(posesFile());
    if (cases.empty())
      for (const auto& [name, pose] : poses)
        if (isEnvironmentCase(name) == envCases) cases.push_back(name);
    const std::filesystem::path work =
        out.empty() ? std::filesystem::temp_directory_path() / "rtr-frame-compare" : std::filesystem::path(out);
    std::filesystem::create_directories(work);
    std::fprintf(stderr, "rtr-frame-compare: device %s\n", ctx.deviceName().c_str());
    if (!curve.empty()) return sppCurve(poses, curve, w, h, threads, spp, ppd, work, !out.empty());
    if (envCases) return environmentCases(ctx, poses, cases, w, h, threads, frames, spp, ppd, work, !out.empty());
    const Limits lim = limits(View::Shaded);
    std::printf(
        "| case | size | GPU frame ms (median of %d) | CPU trace ms (%u threads) | CPU / GPU | CPU Mrays/s "
        "| mean error | max error | failing %% (> %d steps) | ꟻLIP mean | ꟻLIP 99th pct | ꟻLIP max |\n"
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        frames, threads, lim.threshold);
    for (const std::string& name : cases) {
      if (!poses.count(name)) throw Error(posesFile().string() + ": no case named '" + name + "'");
      const ReferenceScene rs = makeScene(name, work);
      const CasePair p =
          renderPair(ctx, rs, poses.at(name), View::Shaded, {.width = w, .height = h, .threads = threads, .benchFrames = frames});
      const CompareResult r = compareEdgeTolerant(p.gpu, p.cpu, lim.threshold);
      const FlipResult fr = flip(p.gpu, p.cpu, {.ppd = ppd, .threads = threads});
      const FlipStats f = fr.stats();
      std::printf("| %s | %ux%u | %.3f | %.1f | %.0f× | %.2f | %.3f | %.0f | %.3f | %.4f | %.3f | %.3f |\n", name.c_str(), w, h,
                  p.gpuMs, p.cpuMs, p.cpuMs / p.gpuMs, double(p.cpuRays) / (p.cpuMs * 1e3), r.meanAbsError, r.maxAbsError,
                  100.0 * r.failingFraction, f.mean, f.p99, f.max);
      std::fflush(stdout);
      if (!out.empty()) {
        savePng(work / (name + "_gpu.png"), p.gpu);
        savePng(work / (name + "_cpu.png"), p.cpu);
        savePng(work / (name + "_err.png"), r.errorMap);
        savePng(work / (name + "_flip.png"), flipHeatMap(fr));
      }
    }
  } catch (const std::exception& e) {
    return cli::fail("rtr-frame-compare", e);  // "rtr-frame-compare: error: ...", exit 1 (2 for usage)
  }
  return 0;
}
