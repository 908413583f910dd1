// rtr-view --headless: the scene rendered offscreen (no window, no display) to a screenshot or timed.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <future>
#include <map>
#include <optional>

#include <sys/resource.h>
#include <unistd.h>

#include "apps/common/cache_options.hpp"
#include "options.hpp"
#include "render/headless.hpp"
#include "render/startup.hpp"
#include "scene/first_look.hpp"
#include "scene/framing.hpp"
#include "vk/context.hpp"
#include "vk/pipeline_cache.hpp"
#include "vk/resources.hpp"

namespace rtr::view {
namespace {

// Whether any pixel is neither black nor the plain colour backdrop (an environment backdrop: taken as lit).
bool anyLit(const ImageRGBA8& img, const render::RenderSettings& s) {
  if (s.backdropBlur >= 0.0f) return true;
  int bg[3];
  for (int c = 0; c < 3; ++c) bg[c] = int(std::lround(255.0f * linearToSrgb(std::clamp(s.background[c], 0.0f, 1.0f))));
  for (size_t i = 0; i < img.pixels.size(); i += 4) {
    const uint8_t* p = &img.pixels[i];
    const bool black = !(p[0] | p[1] | p[2]);
    const bool backdrop = std::abs(p[0] - bg[0]) <= 1 && std::abs(p[1] - bg[1]) <= 1 && std::abs(p[2] - bg[2]) <= 1;
    if (!black && !backdrop) return true;
  }
  return false;
}

void printBench(const std::vector<std::vector<std::pair<std::string, double>>>& frames, const std::string& device) {
  std::map<std::string, std::vector<double>> perPass;
  std::vector<std::string> order;
  for (const auto& f : frames) {
    double total = 0;
    for (const auto& [name, ms] : f) {
      if (!perPass.count(name)) order.push_back(name);
      perPass[name].push_back(ms);
      total += ms;
    }
    if (!perPass.count("total")) order.push_back("total");
    perPass["total"].push_back(total);
  }
  std::printf("| pass | min ms | median ms |  (%zu frames, %s)\n|---|---|---|\n", frames.size(), device.c_str());
  std::string csv;
  for (const auto& name : order) {
    auto v = perPass[name];
    std::sort(v.begin(), v.end());
    std::printf("| %s | %.4f | %.4f |\n", name.c_str(), v.front(), v[v.size() / 2]);
    csv += "csv," + name + "," + std::to_string(v.front()) + "," + std::to_string(v[v.size() / 2]) + "\n";
  }
  std::printf("%s", csv.c_str());
}

std::string mb(uint64_t bytes) { return std::to_string((bytes + (1 << 20) - 1) >> 20) + " MB"; }

// What the address space limit (ulimit -v) leaves this process: a CPU device's memory is the process's own.
uint64_t addressSpaceLeft() {
  rlimit r{};
  if (::getrlimit(RLIMIT_AS, &r) != 0 || r.rlim_cur == RLIM_INFINITY) return UINT64_MAX;
  unsigned long pages = 0;
  if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%lu", &pages) != 1) pages = 0;
    std::fclose(f);
  }
  const uint64_t used = uint64_t(pages) * uint64_t(::sysconf(_SC_PAGESIZE));
  return r.rlim_cur > used ? r.rlim_cur - used : 0;
}

// Before the scene is allocated on the device: its geometry and the frame's targets (about 24 bytes a
// pixel: colour, depth, ids, read-back) against the largest device heap and the address space left,
// and what would fit when they do not.
void checkMemoryFits(const ViewOptions& o, const vk::Context& ctx, const Scene& scene) {
  uint64_t geometry = 0;
  for (const Mesh& m : scene.meshes)
    geometry += m.positions.size() * (12 + 12 + (m.texcoords.empty() ? 0 : 8)) + m.indices.size() * 4 +
                m.clusters.size() * sizeof(Cluster);
  constexpr uint64_t kTargetBytesPerPixel = 24;
  const uint64_t targets = uint64_t(o.width) * o.height * kTargetBytesPerPixel;
  const bool cpu = ctx.deviceType() == VK_PHYSICAL_DEVICE_TYPE_CPU;
  const uint64_t heap = ctx.deviceHeapBytes(), left = cpu ? std::min<uint64_t>(heap, addressSpaceLeft()) : heap;
  if (geometry + targets <= left) return;
  std::string fits = "the geometry alone does not fit";
  if (geometry < left) {
    const uint32_t side = uint32_t(std::sqrt(double(left - geometry) / kTargetBytesPerPixel));
    fits = side ? "a frame of up to " + std::to_string(side) + "x" + std::to_string(side) + " would fit"
                : "no frame fits beside the geometry";
  }
  throw Error("out of memory before uploading " + o.scene + ": needs about " + mb(geometry) + " for its geometry and " +
              mb(targets) + " for the " + std::to_string(o.width) + "x" + std::to_string(o.height) + " frame; " +
              ctx.deviceName() + " has " + mb(left) + (left < heap ? " (the address space left under ulimit -v)" : "") + ": " +
              fits);
}

}  // namespace

namespace {

// Renders; a screenshot is left to `writing`, which writes it while the caller's Vulkan objects go.
int renderHeadless(const ViewOptions& o, std::future<void>& writing) {
  // The phases on the critical path tile the time: each runs from the end of the one before (those of the
  // scene upload are timed inside it), so their sum against the total, measured on its own, shows any time
  // left out. The scene file read runs beside them: its own row, not in the sum.
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); };
  render::StartupTimeline timeline;
  timeline.add("process start to Vulkan (exec, libraries, options)", render::msSinceProcessStart());
  auto last = Clock::now();
  const auto phase = [&](const std::string& name, double lessMs = 0) {
    timeline.add(name, since(last) - lessMs);
    last = Clock::now();
  };
  // The scene file is read on a worker thread while the instance and device are made: neither needs the other.
  SceneRead read(o);
  std::optional<vk::Context> device;
  DeviceChoice choice{};
  std::exception_ptr deviceError;
  try {
    device.emplace(contextOptions(o));
    checkSizeFits(o, *device);
    choice = chooseForDevice(o, *device);
  } catch (...) { deviceError = std::current_exception(); }
  phase("instance and device");
  Scene scene = read.take(deviceError);
  const vk::Context& ctx = *device;
  checkMemoryFits(o, ctx, scene);
  phase("waiting for the scene file read");
  timeline.addBeside("scene file read", read.ms(), "instance and device");
  // A load that takes over half a second says how far it is: one line rewritten on a terminal, else a
  // line a second.
  const auto loadStart = Clock::now();
  auto lastShown = loadStart;
  const bool terminal = ::isatty(2);
  const render::LoadProgress progress = [&](const char* what, size_t done, size_t total) {
    if (since(loadStart) < 500 || (done < total && since(lastShown) < (terminal ? 250 : 1000))) return;
    std::fprintf(stderr, "%srtr-view: %s %zu/%zu%s", terminal ? "\r" : "", what, done, total,
                 terminal && done < total ? "" : "\n");
    lastShown = Clock::now();
  };
  const bool wait = o.waitTextures.value_or(true);
  const std::unique_ptr<TextureCache> textureCache = cli::textureCache(!o.textureCache);
  render::RenderSettings settings = sceneSettings(o, scene);
  settings.shading = choice.shading;
  settings.clip = choice.computeClip;
  // The first frame's pipelines need the scene's kinds, not its buffers: made on a thread of their own
  // while the scene uploads, waited for after it.
  render::PipelinesAhead ahead(ctx, scene, settings, o.env.hasEnvironment());
  phase("settings, the pipelines' thread started");  // a thread's start may take this one off its core a while
  render::GpuScene gpuScene(ctx, scene, choice.mips, progress, render::GeometryUpload::Auto,
                            wait ? render::TextureLoad::Wait : render::TextureLoad::Deferred, textureCache.get(),
                            size_t(o.textureBatchMb) << 20);
  const auto& st = gpuScene.stats();  // the texture phases: once they are in
  char uploadRow[96];                 // the path taken and its rate (docs/startup.md, "Geometry upload")
  std::snprintf(uploadRow, sizeof uploadRow, "geometry upload (%.1f MB, %.2f GB/s, %s)", double(st.geometryBytes) * 1e-6,
                st.geometryMs > 0 ? double(st.geometryBytes) / st.geometryMs * 1e-6 : 0.0, enumName(st.geometryUpload));
  timeline.add(uploadRow, st.geometryMs);
  // The decode runs beside the upload: what it adds to the critical path is the wait for it after the
  // upload and the chains' unpacking into staging memory with the texture upload.
  if (wait) timeline.add("texture decode", st.decodeMs - st.decodeBesideMs + st.decodeWaitMs);
  if (wait) timeline.addBeside("textures decoded", st.decodeBesideMs, "the geometry upload");
  if (wait) timeline.add("texture upload", st.textureUploadMs), timeline.add("mips", st.mipsMs);
  if (wait && st.cacheReadbackMs > 0) timeline.add("texture cache read-back", st.cacheReadbackMs);
  last = Clock::now();
  render::Renderer::Prepared prepared = ahead.take();
  phase("waiting for the pipelines");
  const vk::PipelineStats made = ctx.pipelineCache().besideStats();
  timeline.addBeside(render::pipelineRow("pipelines made ahead", made), made.ms, "the scene upload");
  const double pipelineMsBefore = ctx.pipelineCache().stats().ms;
  std::fprintf(stderr,
               "rtr-view: %s on %s (%s): %u meshes (%u with 16-bit indices), %u triangles, %u textures; "
               "geometry %.0f ms (%.2f GB/s)",
               o.scene.c_str(), ctx.deviceName().c_str(), ctx.driverInfo().c_str(), st.meshes, st.meshes16, st.triangles,
               st.textures, st.geometryMs, st.geometryMs > 0 ? double(st.geometryBytes) / st.geometryMs * 1e-6 : 0.0);
  if (wait)
    std::fprintf(stderr, ", decode %.0f ms, texture upload %.0f ms, mips %.3f ms GPU", st.decodeMs, st.textureUploadMs,
                 st.mipGpuMs);
  if (wait && textureCache)
    std::fprintf(stderr, "; texture cache: %u hits, %u misses (%s)", st.cacheHits, st.cacheMisses, textureCache->dir().c_str());
  else if (!wait && st.textures)
    std::fprintf(stderr, ", textures decoding (frames show the materials' factors: --no-wait-textures)");
  std::fprintf(stderr, "\n");
  const CameraPose pose = startPose(o, scene);
  const Lens lens = fitDepthRange(startLens(o, scene), scene.bounds(), pose);
  render::HeadlessRenderer renderer(ctx, gpuScene, {o.width, o.height}, std::move(prepared));
  if (settings.shading == render::ShadingPath::Visibility && !renderer.renderer().visibilityRefusal().empty())
    std::fprintf(stderr, "rtr-view: warning: %s: frames take the forward path\n",
                 renderer.renderer().visibilityRefusal().c_str());
  const auto env = loadEnvironment(o, ctx);
  renderer.renderer().setEnvironment(env);
  const double setupPipelineMs = ctx.pipelineCache().stats().ms - pipelineMsBefore;
  phase("renderer setup (start pose, targets)", setupPipelineMs);
  std::optional<render::HeadlessFrame> first;
  // --no-wait-textures: the first frame is rendered before the textures are in (the materials' factors);
  // they are taken in after it, for the frames that follow.
  if (o.timings || !wait) first = renderer.render(pose, lens, settings, 1);
  if (o.timings) {
    const double totalMs = render::msSinceProcessStart();
    const vk::PipelineStats ps = ctx.pipelineCache().stats();
    timeline.add(render::pipelineRow("pipeline creation", ps), ps.ms);
    phase("first frame complete (record, GPU, read-back)", ps.ms - pipelineMsBefore - setupPipelineMs);
    std::fprintf(stderr, "rtr-view: %s", timeline.format(totalMs).c_str());
  }
  // Then frames 2..K (--frames K) take in, between frames, the textures that came in (GpuScene::updateTextures),
  // as the window does; with --timings frames go on until the last is in, each one's line printed.
  int rendered = first ? 1 : 0;
  double firstTexturedAt = 0, allInAt = 0;
  while (!wait && !gpuScene.texturesReady() && (rendered < o.frames || o.timings)) {
    gpuScene.updateTextures();
    const size_t in = gpuScene.texturesIn();
    const auto t = Clock::now();
    first = renderer.render(pose, lens, settings, 1);
    ++rendered;
    if (in > 0 && firstTexturedAt == 0) firstTexturedAt = render::msSinceProcessStart();
    if (in == st.textures) allInAt = render::msSinceProcessStart();  // the frame with every texture is done
    if (o.timings)
      std::fprintf(stderr, "rtr-view: frame %d done at %.0f ms: %.1f ms, textures in %zu/%u\n", rendered,
                   render::msSinceProcessStart(), since(t), in, st.textures);
  }
  if (gpuScene.updateTextures(true) && allInAt == 0) allInAt = render::msSinceProcessStart();
  if (!wait && o.timings && st.textures)  // how long the textures took, after the first frame
    std::fprintf(stderr,
                 "rtr-view: textures in at %.0f ms from process start (the first frame with some done at %.0f ms): decode %.0f "
                 "ms (worker threads), upload and mips %.0f ms (mips %.3f ms GPU); texture cache: %u hits, %u misses\n",
                 allInAt, firstTexturedAt, st.decodeMs, st.textureUploadMs, st.mipGpuMs, st.cacheHits, st.cacheMisses);
  if (o.bench > 0) {
    // The timed frames read no counters back (RenderSettings::counters); one frame after them does, for the lines below.
    render::RenderSettings timed = settings;
    timed.counters = false;
    renderer.bench(pose, lens, timed, 10);  // warm-up
    printBench(renderer.bench(pose, lens, timed, o.bench), ctx.deviceName());
    renderer.bench(pose, lens, settings, 1);
    if (const auto c = renderer.renderer().cullStats(0)) {
      const double n = std::max(1u, c->clusters);
      std::printf(
          "cull: %u clusters; listed early %u, late %u; culled by frustum %u (%.1f %%), cone %u (%.1f %%), "
          "occlusion %u (%.1f %%), not in the level-of-detail cut %u; %u triangles listed\n",
          c->clusters, c->early, c->late, c->frustum, 100 * c->frustum / n, c->cone, 100 * c->cone / n, c->occlusion,
          100 * c->occlusion / n, c->lod, c->triangles);
      std::printf("cull: %u cluster tests and %u tree node tests (both phases), %u instances culled whole\n", c->tested, c->nodes,
                  c->instancesCulled);
    }
    if (settings.raster != render::RasterPath::Hardware)
      if (const auto h = renderer.renderer().handOffTriangles(0)) {
        std::printf("raster hw: %u triangles handed off\n", *h);
        std::printf("raster clip: %u triangles clipped in compute\n", renderer.renderer().clippedTriangles(0).value_or(0));
        const render::ComputeRaster::MediumCounts m =
            renderer.renderer().mediumTriangles(0).value_or(render::ComputeRaster::MediumCounts{});
        std::printf("raster medium: %u triangles (%u past the list, drawn by their own thread; %u of 16 lanes, %u of 32)\n",
                    m.total(), m.pastList, m.narrow, m.wide);
        if (*h > renderer.renderer().handOffCapacity())
          std::fprintf(stderr, "rtr-view: warning: the hand-off list holds %u triangles: %u were not drawn\n",
                       renderer.renderer().handOffCapacity(), *h - renderer.renderer().handOffCapacity());
      }
  }
  if (!o.screenshot.empty()) {
    render::HeadlessFrame frame = first && rendered >= o.frames
                                      ? std::move(*first)
                                      : renderer.render(pose, lens, settings, std::max(1, o.frames - rendered));
    const std::string empty = emptyImageWarning(scene, pose, lens, float(o.width) / float(o.height),
                                                anyLit(frame.image, settings), settings.lights.lights.size());
    if (!empty.empty()) std::fprintf(stderr, "rtr-view: warning: %s\n", empty.c_str());
    // Compressed on all cores while the renderer, the scene and the device are torn down: the two overlap.
    writing = std::async(std::launch::async, [&o, image = std::move(frame.image)] {
      saveImage(o.screenshot, image, {o.force ? Replace::Yes : Replace::No, true});
    });
    for (const auto& [name, ms] : frame.gpuTimes) std::fprintf(stderr, "  %s: %.3f ms GPU\n", name.c_str(), ms);
  }
  printPipelineStats(o, ctx);
  return 0;
}

}  // namespace

int runHeadless(const ViewOptions& o) {
  std::future<void> writing;
  int status = 0;
  try {
    status = stage("uploading or rendering " + o.scene, [&] { return renderHeadless(o, writing); });
  } catch (const vk::OutOfMemory& e) { throw Error("out of memory while uploading or rendering " + o.scene + ": " + e.what()); }
  if (writing.valid()) {
    writing.get();  // rethrows a write error
    std::printf("%s\n", std::filesystem::absolute(o.screenshot).c_str());
  }
  return status;
}

}  // namespace rtr::view
