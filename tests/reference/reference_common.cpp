#include "reference_common.hpp"
#include "test_paths.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <tuple>

#include "core/error.hpp"
#include "render/environment_maps.hpp"
#include "core/camera.hpp"
#include "render/headless.hpp"
#include "vk/glsl.hpp"
#include "vk/pipeline.hpp"
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

namespace {
std::string readAll(const std::filesystem::path& f) {
  std::ifstream in(f, std::ios::binary);
  if (!in) throw Error(f.string() + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}
}  // namespace

std::filesystem::path shaderFolderWith(const ShaderEdit& edit) {
  const std::filesystem::path dir = outDir() / "work" / ("shaders_" + edit.name), src = dir / "src";
  std::filesystem::create_directories(dir);
  for (const auto& e : std::filesystem::directory_iterator(vk::shaderDir()))
    if (e.path().extension() == ".spv")
      std::filesystem::copy_file(e.path(), dir / e.path().filename(), std::filesystem::copy_options::overwrite_existing);
  std::filesystem::remove_all(src);
  std::filesystem::copy(sourceDir() / "shaders", src, std::filesystem::copy_options::recursive);
  if (!edit.from.empty()) {
    std::string text = readAll(src / edit.file);
    const size_t at = text.find(edit.from);
    if (at == std::string::npos) throw Error(edit.file + " no longer contains '" + edit.from + "'");
    text.replace(at, edit.from.size(), edit.to);
    std::ofstream(src / edit.file, std::ios::binary | std::ios::trunc) << text;
  }
  for (const char* shader : {"pbr.frag", "vis_shade.comp"}) {  // every variant of each (variants.h)
    const vk::SpirvModule m = vk::compileGlsl(src / shader, {src, src / "shared"});
    std::ofstream out(dir / (std::string(shader) + ".spv"), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(m.code.data()), std::streamsize(m.code.size() * sizeof(uint32_t)));
    if (!out) throw Error("cannot write " + (dir / shader).string() + ".spv");
  }
  return dir;
}

std::filesystem::path posesFile() { return sourceDir() / "tests/reference/poses.txt"; }

std::filesystem::path outDir() {
  const std::filesystem::path d = test::binaryDir() / "reference-out";
  std::filesystem::create_directories(d);
  return d;
}

trace::TraceSettings traceSettings(const ReferenceScene& rs, const PoseEntry& pe, View view, const PairOptions& o) {
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
  if (rs.environment) {
    ts.environment = rs.environment;
    ts.spp = o.spp;
    ts.environmentVisible = false;
    ts.background = glm::vec3(kUncovered);
  }
  return ts;
}

ImageF traceCase(const ReferenceScene& rs, const PoseEntry& pe, View view, const PairOptions& o, trace::RenderStats* stats) {
  const trace::Tracer tracer(rs.scene, o.threads);
  ImageF img;
  const trace::RenderStats st = tracer.render(traceSettings(rs, pe, view, o), img);
  if (stats) *stats = st;
  return img;
}

CasePair renderPair(const vk::Context& ctx, const ReferenceScene& rs, const PoseEntry& pe, View view, const PairOptions& o) {
  const std::optional<std::filesystem::path>& shaderDir = o.shaderDir;
  const trace::TraceSettings ts = traceSettings(rs, pe, view, o);
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
  if (rs.environment) {
    s.background = glm::vec3(kUncovered);
    s.backdropBlur = -1.0f;
  }
  const Lens lens = tracer.resolveLens(ts);  // the tracer's near/far: depth / far means the same on both sides

  std::string previous;
  const char* env = std::getenv("RTR_SHADER_DIR");
  if (env) previous = env;
  if (shaderDir) setenv("RTR_SHADER_DIR", shaderDir->c_str(), 1);
  std::optional<render::GpuScene> gpuScene;
  std::optional<render::HeadlessRenderer> renderer;
  std::shared_ptr<const render::EnvironmentMaps> maps;
  render::HeadlessFrame f;
  try {  // the renderer loads a path's shaders on its first frame: keep the folder set until then
    gpuScene.emplace(ctx, rs.scene, render::MipMode::Compute);
    renderer.emplace(ctx, *gpuScene, VkExtent2D{o.width, o.height});
    if (rs.environment) {
      maps = std::make_shared<const render::EnvironmentMaps>(ctx, *rs.environment);
      renderer->renderer().setEnvironment(maps);
    }
    f = renderer->render(pe.pose, lens, s, 1, true);
  } catch (...) {
    if (shaderDir) env ? setenv("RTR_SHADER_DIR", previous.c_str(), 1) : unsetenv("RTR_SHADER_DIR");
    throw;
  }
  if (shaderDir) env ? setenv("RTR_SHADER_DIR", previous.c_str(), 1) : unsetenv("RTR_SHADER_DIR");
  CasePair pair{toSrgb8(f.sceneColor), std::move(f.image), toSrgb8(cpu)};
  pair.gpuLinear = std::move(f.sceneColor);
  pair.cpuLinear = std::move(cpu);
  if (maps) pair.prefilterMs = maps->times();
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

EnvError envError(const ImageF& test, const ImageF& ref, const std::vector<bool>* mask) {
  if (test.width != ref.width || test.height != ref.height) throw Error("envError: the images differ in size");
  EnvError e;
  auto used = [&](size_t i) { return test.pixels[i].r != kUncovered && ref.pixels[i].r != kUncovered && (!mask || (*mask)[i]); };
  for (size_t i = 0; i < test.pixels.size(); ++i) {
    if (!used(i)) continue;
    ++e.pixels;
    for (int c = 0; c < 3; ++c) {
      const double d = std::abs(double(test.pixels[i][c]) - double(ref.pixels[i][c]));
      e.meanAbs += d;
      e.maxAbs = std::max(e.maxAbs, d);
      e.meanRef += ref.pixels[i][c];
    }
  }
  if (!e.pixels) return e;
  e.meanAbs /= 3.0 * double(e.pixels);
  e.meanRef /= 3.0 * double(e.pixels);
  const double floor = 3.0 * 0.05 * e.meanRef;
  for (size_t i = 0; i < test.pixels.size(); ++i) {
    if (!used(i)) continue;
    const glm::vec3 a(test.pixels[i]), b(ref.pixels[i]);
    const glm::vec3 d = glm::abs(a - b);
    e.meanPixelRelative += double(d.x + d.y + d.z) / std::max(floor, double(b.x + b.y + b.z));
  }
  e.meanPixelRelative /= double(e.pixels);
  return e;
}

std::vector<int> partOfPixels(const ReferenceScene& rs, const PoseEntry& pe, uint32_t w, uint32_t h, const ImageF& coverage) {
  const Lens lens = fitDepthRange(Lens{.fovYDeg = pe.fovYDeg}, rs.scene.bounds(), pe.pose);
  const glm::mat4 vp = projectionMatrix(lens, float(w) / float(h)) * viewMatrix(pe.pose);
  std::vector<glm::vec2> centres;
  for (const ReferenceScene::Part& p : rs.parts) {
    const glm::vec4 c = vp * glm::vec4(p.centre, 1.0f);
    centres.emplace_back((c.x / c.w * 0.5f + 0.5f) * float(w), (c.y / c.w * 0.5f + 0.5f) * float(h));
  }
  std::vector<int> out(size_t(w) * h, -1);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      if (coverage.at(x, y).r == kUncovered) continue;
      float best = 1e30f;
      for (size_t k = 0; k < centres.size(); ++k) {
        const glm::vec2 d = centres[k] - glm::vec2(float(x) + 0.5f, float(y) + 0.5f);
        if (glm::dot(d, d) < best) best = glm::dot(d, d), out[size_t(y) * w + x] = int(k);
      }
    }
  return out;
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
