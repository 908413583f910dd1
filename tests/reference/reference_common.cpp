#include "reference_common.hpp"
#include "test_paths.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <tuple>

#include "render/headless.hpp"
#include "trace/tracer.hpp"

namespace rtr::reftest {

const char* viewName(View v) {
  switch (v) {
    case View::Shaded: return "shaded";
    case View::Normals: return "normals";
    case View::Depth: return "depth";
  }
  return "?";
}

// Why these numbers: docs/reference-tests.md ("Thresholds").
Limits limits(View v) {
  switch (v) {
    case View::Shaded: return {3, 0.001};
    case View::Normals: return {2, 0.001};
    case View::Depth: return {2, 0.001};
  }
  return {0, 0.0};
}

Limits limits(const std::string& caseName, View v) {
  if (v == View::Shaded && caseName.ends_with("_textured")) return {8, 0.01};
  return limits(v);
}

std::filesystem::path posesFile() { return sourceDir() / "tests/reference/poses.txt"; }

std::filesystem::path outDir() {
  const std::filesystem::path d = test::binaryDir() / "reference-out";
  std::filesystem::create_directories(d);
  return d;
}

CasePair renderPair(const vk::Context& ctx, const ReferenceScene& rs, const PoseEntry& pe, View view, const PairOptions& o) {
  const std::optional<std::filesystem::path>& shaderDir = o.shaderDir;
  trace::TraceSettings ts;
  ts.width = o.width;
  ts.height = o.height;
  ts.pose = pe.pose;
  ts.lens.fovYDeg = pe.fovYDeg;
  ts.shading = view == View::Shaded    ? trace::Shading::Pbr
               : view == View::Normals ? trace::Shading::Normals
                                       : trace::Shading::Depth;
  ts.shadows = false;  // the GPU renderer has no shadows
  ts.bounces = 0;      // nor reflections
  ts.threads = o.threads;
  ts.lights = rs.lights;
  const trace::Tracer tracer(rs.scene, o.threads);
  ImageF cpu;
  const trace::RenderStats stats = tracer.render(ts, cpu);
  if (view == View::Depth)
    for (glm::vec4& p : cpu.pixels)  // miss (1.0; geometry is below 1/1.01 by fitDepthRange) -> GPU clear 0
      if (p.r > 0.995f) p = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);

  render::RenderSettings s;
  s.mode = view == View::Shaded ? VIEW_SHADED : view == View::Normals ? VIEW_NORMAL : VIEW_LINEAR_DEPTH;
  s.mosaic = render::MosaicMode::Off;
  s.raster = o.raster;
  s.lights = rs.lights;
  const Lens lens = tracer.resolveLens(ts);  // the tracer's near/far: depth / far means the same on both sides

  std::string previous;
  const char* env = std::getenv("RTR_SHADER_DIR");
  if (env) previous = env;
  if (shaderDir) setenv("RTR_SHADER_DIR", shaderDir->c_str(), 1);
  std::optional<render::GpuScene> gpuScene;
  std::optional<render::HeadlessRenderer> renderer;
  render::HeadlessFrame f;
  try {  // the renderer loads a path's shaders on its first frame: keep the folder set until then
    gpuScene.emplace(ctx, rs.scene, render::MipMode::Compute);
    renderer.emplace(ctx, *gpuScene, VkExtent2D{o.width, o.height});
    f = renderer->render(pe.pose, lens, s, 1, true);
  } catch (...) {
    if (shaderDir) env ? setenv("RTR_SHADER_DIR", previous.c_str(), 1) : unsetenv("RTR_SHADER_DIR");
    throw;
  }
  if (shaderDir) env ? setenv("RTR_SHADER_DIR", previous.c_str(), 1) : unsetenv("RTR_SHADER_DIR");
  CasePair pair{toSrgb8(f.sceneColor), std::move(f.image), toSrgb8(cpu)};
  if (o.benchFrames > 0) {
    renderer->bench(pe.pose, lens, s, 10);  // warm-up
    std::vector<double> totals;
    for (const auto& frame : renderer->bench(pe.pose, lens, s, o.benchFrames)) {
      double sum = 0;
      for (const auto& pass : frame) sum += pass.second;
      totals.push_back(sum);
    }
    std::sort(totals.begin(), totals.end());
    pair.gpuMs = totals[totals.size() / 2];
    pair.cpuMs = stats.seconds * 1e3;
    pair.cpuRays = stats.primaryRays + stats.shadowRays + stats.reflectionRays;
  }
  return pair;
}

std::string blankReason(const ImageRGBA8& img) {
  size_t bright = 0;
  std::set<std::tuple<uint8_t, uint8_t, uint8_t>> colours;
  for (size_t i = 0; i + 3 < img.pixels.size(); i += 4) {
    const uint8_t* p = &img.pixels[i];
    if (std::max({p[0], p[1], p[2]}) > 2) ++bright;
    colours.emplace(p[0], p[1], p[2]);
  }
  const size_t n = size_t(img.width) * img.height;
  if (double(bright) < 0.05 * double(n)) return "(nearly) black image";
  if (colours.size() < 2) return "one colour only";
  return "";
}

void writeOutputs(const std::string& id, const CasePair& pair, const CompareResult& r, const Limits& lim) {
  const std::filesystem::path d = outDir();
  savePng(d / (id + "_gpu.png"), pair.gpu);
  savePng(d / (id + "_cpu.png"), pair.cpu);
  savePng(d / (id + "_err.png"), r.errorMap);
  char line[256];
  std::snprintf(line, sizeof line,
                "%-24s threshold %d  failing %6.3f%% (limit %.2f%%)  mean %.3f  max %3.0f  max(passing) %2.0f\n", id.c_str(),
                lim.threshold, 100.0 * r.failingFraction, 100.0 * lim.maxFailingFraction, r.meanAbsError, r.maxAbsError,
                r.maxAbsErrorPassing);
  std::ofstream(d / (id + ".txt")) << line;
  std::fputs(line, stdout);
}

}  // namespace rtr::reftest
