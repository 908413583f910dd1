// rtr-view: the Vulkan viewer. Headless (--headless: no window, no display) or in a GLFW window.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <chrono>
#include <cstdio>
#include <future>
#include <optional>
#include <iostream>
#include <map>

#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include "core/cli.hpp"
#include "core/error.hpp"
#include "options.hpp"
#include "render/headless.hpp"
#include "render/startup.hpp"
#include "scene/framing.hpp"
#include "scene/load.hpp"
#include "vk/context.hpp"
#include "vk/pipeline_cache.hpp"
#include "vk/resources.hpp"

namespace rtr::view {

CameraPose startPose(const ViewOptions& o, const Scene& scene) {
  if (o.camera) return *o.camera;
  if (scene.defaultView) return *scene.defaultView;
  return framingPose(scene, o.lens, float(o.width) / float(o.height));
}

void checkSizeFits(const ViewOptions& o, const vk::Context& ctx) {
  const uint32_t max = ctx.properties().limits.maxImageDimension2D;
  if (o.width > max || o.height > max)
    throw UsageError("--size " + std::to_string(o.width) + "x" + std::to_string(o.height) + ": " + ctx.deviceName() +
                     " makes images of at most " + std::to_string(max) + " pixels a side");
}

namespace {

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

}  // namespace

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
              ctx.deviceName() + " has " + mb(left) + (left < heap ? " (the address space left under ulimit -v)" : "") +
              ": " + fits);
}

render::RenderSettings sceneSettings(const ViewOptions& o, const Scene& scene) {
  render::RenderSettings s = o.settings;
  s.lights = resolveLights(scene, o.lightOptions);
  if (!s.lights.note.empty()) std::fprintf(stderr, "rtr-view: note: %s\n", s.lights.note.c_str());
  return s;
}

vk::ContextOptions contextOptions(const ViewOptions& o) {
  vk::ContextOptions co = vk::optionsFromEnvironment();
  if (o.validation) co.validation = true;
  if (!o.device.empty()) co.device = o.device;
  if (!o.pipelineCache) co.pipelineCacheDir.clear();
  return co;
}

DeviceChoice chooseForDevice(const ViewOptions& o, const vk::Context& ctx) {
  const render::DeviceDefaults d = render::deviceDefaults(ctx.deviceType());
  DeviceChoice c{o.shadingGiven ? o.settings.shading : d.shading, o.mipsGiven ? o.mips : d.mips};
  // No " on " in this line: scripts take the first line with one for the device line below.
  std::fprintf(stderr, "rtr-view: %s: %s shading (%s), %s mips (%s)", ctx.deviceName().c_str(),
               enumName(c.shading), o.shadingGiven ? "--shading-path" : "default",
               enumName(c.mips), o.mipsGiven ? "--mips" : "default");
  if (!o.shadingGiven || !o.mipsGiven) std::fprintf(stderr, ": the defaults for %s (docs/startup.md)", d.why);
  std::fprintf(stderr, "\n");
  if (const float max = render::maxAnisotropy(ctx); o.settings.sampler.anisotropy > max)
    std::fprintf(stderr, "rtr-view: note: --anisotropy %g: %s samples with at most %g\n", o.settings.sampler.anisotropy,
                 ctx.deviceName().c_str(), max);
  return c;
}

namespace {

bool allBlack(const ImageRGBA8& img) {
  for (size_t i = 0; i < img.pixels.size(); i += 4)
    if (img.pixels[i] | img.pixels[i + 1] | img.pixels[i + 2]) return false;
  return true;
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

}  // namespace

namespace {

// Renders; a screenshot is left to `writing`, which writes it while the caller's Vulkan objects go.
int renderHeadless(const ViewOptions& o, std::future<void>& writing) {
  // The phases tile the time: each runs from the end of the one before (those of the scene upload are
  // timed inside it), so their sum against the total, measured on its own, shows any time left out.
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); };
  render::StartupTimeline timeline;
  timeline.add("process start to Vulkan (exec, libraries, options)", render::msSinceProcessStart());
  auto last = Clock::now();
  const auto phase = [&](const std::string& name, double lessMs = 0) {
    timeline.add(name, since(last) - lessMs);
    last = Clock::now();
  };
  vk::Context ctx(contextOptions(o));
  checkSizeFits(o, ctx);
  const DeviceChoice choice = chooseForDevice(o, ctx);
  phase("instance and device");
  Scene scene = loadScene(o.scene, o.load);
  checkMemoryFits(o, ctx, scene);
  phase("scene file read");
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
  render::GpuScene gpuScene(ctx, scene, choice.mips, progress, render::GeometryUpload::Auto,
                            wait ? render::TextureLoad::Wait : render::TextureLoad::Deferred);
  const auto& st = gpuScene.stats();  // the texture phases: once they are in
  if (wait) timeline.add("texture decode", st.decodeMs);
  timeline.add("geometry upload", st.geometryMs);
  if (wait) timeline.add("texture upload", st.textureUploadMs), timeline.add("mips", st.mipsMs);
  last = Clock::now();
  const double pipelineMsBefore = ctx.pipelineCache().stats().ms;
  std::fprintf(stderr, "rtr-view: %s on %s (%s): %u meshes (%u with 16-bit indices), %u triangles, %u textures; "
               "geometry %.0f ms (%.2f GB/s)",
               o.scene.c_str(), ctx.deviceName().c_str(), ctx.driverInfo().c_str(), st.meshes, st.meshes16,
               st.triangles, st.textures, st.geometryMs,
               st.geometryMs > 0 ? double(st.geometryBytes) / st.geometryMs * 1e-6 : 0.0);
  if (wait)
    std::fprintf(stderr, ", decode %.0f ms, texture upload %.0f ms, mips %.3f ms GPU", st.decodeMs, st.textureUploadMs,
                 st.mipGpuMs);
  else if (st.textures)
    std::fprintf(stderr, ", textures decoding (frames show the materials' factors: --no-wait-textures)");
  std::fprintf(stderr, "\n");
  const CameraPose pose = startPose(o, scene);
  const Lens lens = fitDepthRange(o.lens, scene.bounds(), pose);
  render::RenderSettings settings = sceneSettings(o, scene);
  settings.shading = choice.shading;
  render::HeadlessRenderer renderer(ctx, gpuScene, {o.width, o.height});
  const double setupPipelineMs = ctx.pipelineCache().stats().ms - pipelineMsBefore;
  phase("renderer setup (start pose, targets)", setupPipelineMs);
  std::optional<render::HeadlessFrame> first;
  // --no-wait-textures: the first frame is rendered before the textures are in (the materials' factors);
  // they are taken in after it, for the frames that follow.
  if (o.timings || !wait) first = renderer.render(pose, lens, settings, 1);
  if (o.timings) {
    const double totalMs = render::msSinceProcessStart();
    const vk::PipelineStats ps = ctx.pipelineCache().stats();
    char name[120];
    if (ps.reported == ps.created)
      std::snprintf(name, sizeof name, "pipeline creation (%u, %u from the cache)", ps.created, ps.cacheHits);
    else
      std::snprintf(name, sizeof name, "pipeline creation (%u, cache hits not reported)", ps.created);
    timeline.add(name, ps.ms);
    phase("first frame complete (record, GPU, read-back)", ps.ms - pipelineMsBefore - setupPipelineMs);
    std::fprintf(stderr, "rtr-view: %s", timeline.format(totalMs).c_str());
  }
  if (gpuScene.updateTextures(true) && o.timings)  // how long the textures took, after the first frame
    std::fprintf(stderr, "rtr-view: textures in at %.0f ms from process start: decode %.0f ms (worker threads), "
                 "upload and mips %.0f ms (mips %.3f ms GPU)\n", render::msSinceProcessStart(), st.decodeMs,
                 st.textureUploadMs, st.mipGpuMs);
  if (o.bench > 0) {
    renderer.bench(pose, lens, settings, 10);  // warm-up
    printBench(renderer.bench(pose, lens, settings, o.bench), ctx.deviceName());
    if (const auto c = renderer.renderer().cullStats(0)) {
      const double n = std::max(1u, c->clusters);
      std::printf("cull: %u clusters; listed early %u, late %u; culled by frustum %u (%.1f %%), cone %u (%.1f %%), "
                  "occlusion %u (%.1f %%)\n", c->clusters, c->early, c->late, c->frustum, 100 * c->frustum / n, c->cone,
                  100 * c->cone / n, c->occlusion, 100 * c->occlusion / n);
    }
  }
  if (!o.screenshot.empty()) {
    render::HeadlessFrame frame = first && o.frames <= 1 ? std::move(*first)
                                                         : renderer.render(pose, lens, settings, std::max(1, o.frames));
    if (settings.lights.lights.empty() && allBlack(frame.image))
      std::fprintf(stderr, "rtr-view: warning: the image is all black (no lights: --no-default-light)\n");
    // Compressed on all cores while the renderer, the scene and the device are torn down (on lavapipe
    // a good part of the PNG's time).
    writing = std::async(std::launch::async, [&o, image = std::move(frame.image)] {
      saveImage(o.screenshot, image, {o.force ? Replace::Yes : Replace::No, true});
    });
    for (const auto& [name, ms] : frame.gpuTimes) std::fprintf(stderr, "  %s: %.3f ms GPU\n", name.c_str(), ms);
  }
  return 0;
}

}  // namespace

int runHeadless(const ViewOptions& o) {
  std::future<void> writing;
  int status = 0;
  try {
    status = stage("uploading or rendering " + o.scene, [&] { return renderHeadless(o, writing); });
  } catch (const vk::OutOfMemory& e) {
    throw Error("out of memory while uploading or rendering " + o.scene + ": " + e.what());
  }
  if (writing.valid()) {
    writing.get();  // rethrows a write error
    std::printf("%s\n", std::filesystem::absolute(o.screenshot).c_str());
  }
  return status;
}

}  // namespace rtr::view

int main(int argc, char** argv) {
  using namespace rtr;
  view::ViewOptions o;
  CLI::App app{"rtr-view: real-time Vulkan viewer (PBR, alpha masking, compute mosaic, debug views).\n"
               "Keys: W/S/A/D/E/Q move, Shift faster, Ctrl slower, right mouse button toggles mouse-look,\n"
               "1-7 views (shaded, mip level, linear depth, depth derivatives, normal, view dir, light dir),\n"
               "8/9/0 BRDF D/F/G, -/= diffuse/specular, M mosaic off/compute/graphics, [ ] LOD bias,\n"
               "C print camera pose, F1 or H settings panel, Home start pose, R ray-trace the view on the CPU (again: hide),\n"
               "T tracer shading phong/pbr/normals, Y shadows, U reflections, O orthographic, F frame the scene,\n"
               "Esc quit.",
               "rtr-view"};
  std::string camera, size = "1280x720", mips = enumName(o.mips), mosaic = "off", light, lightColor,
              ambient = "0.02", mtl,
              filter = enumName(o.settings.sampler.filter);
  bool waitTextures = true;
  std::string shadingPath = enumName(o.settings.shading), raster = enumName(o.settings.raster);
  app.add_option("scene", o.scene, "scene file (.rtrscene, .comp5892mesh, .obj, .obj.zst)")->required();
  app.add_option("--mtl", mtl, "OBJ: take the materials from this MTL (default: the OBJ's mtllib, else NAME.mtl beside it)");
  app.add_flag("--headless", o.headless, "render offscreen: no window, no display needed");
  app.add_option("--size", size, "image size WxH")->capture_default_str()
      ->check(cli::checked([](const std::string& t) { cli::parseSize("--size", t, view::kMaxSize); }, "WxH"));
  app.add_option("--camera", camera, "start pose x,y,z,yaw,pitch (degrees)")
      ->check(cli::checked([](const std::string& t) { cli::parsePose("--camera", t); }, "X,Y,Z,YAW,PITCH"));
  app.add_option("--fov", o.lens.fovYDeg, "vertical field of view in degrees")->capture_default_str()
      ->check(cli::number(0, 180, true));
  app.add_option("--mode", o.settings.mode, "view mode 1-13 (1 shaded)")->check(cli::integer(1, VIEW_COUNT))->capture_default_str();
  app.add_option("--frames", o.frames, "frames to render before the screenshot")->check(cli::integer(1, 100000));
  app.add_option("--screenshot", o.screenshot, "write the rendered frame (not the overlay): .png, .jpg, .exr or .hdr");
  app.add_flag("--force", o.force, "overwrite an existing screenshot");
  CLI::Option* mipsOpt = app.add_option("--mips", mips, "mip generation: compute (several levels per dispatch) | blit | auto (per texture: compute "
                                        "when small, blit when large) "
                                        "(default: the device's fastest, docs/startup.md)")
                         ->check(cli::oneOf<render::MipMode>());
  app.add_option("--mosaic", mosaic, "post process: off (the scene plainly) | compute | graphics (the brief's captures: compute)")
      ->check(cli::oneOf<render::MosaicMode>())->capture_default_str();
  CLI::Option* shadingOpt =
      app.add_option("--shading-path", shadingPath, "shaded view: visibility (ids rasterised, BRDF in compute) | forward "
                     "(default: the device's fastest, docs/startup.md)")
          ->check(cli::oneOf<render::ShadingPath>());
  app.add_option("--raster", raster, "visibility ids: hardware | compute (64-bit atomics) | auto (the device's default)")
      ->check(cli::oneOf<render::RasterPath>())->capture_default_str();
  std::string cull = "off";
  app.add_option("--cull", cull, "compute raster: two-phase cluster culling (frustum, back-face cones, depth pyramid) on | off")
      ->check(CLI::IsMember({"on", "off"}))->capture_default_str();
  app.add_option("--lod-bias", o.settings.lodBias, "mipmap LOD bias")->check(cli::number(-16, 16));
  app.add_option("--filter", filter, "texture filter: trilinear | nearest-mip (nearest level, bilinear in it) | nearest "
                 "(nearest texel of the nearest level)")
      ->check(cli::oneOf<render::TextureFilter>())->capture_default_str();
  app.add_option("--anisotropy", o.settings.sampler.anisotropy,
                 "anisotropic filtering, 1 (off) up to the device's maxSamplerAnisotropy (more is clamped, with a note)")
      ->check(cli::number(1, 64))->capture_default_str();
  CLI::Option* lightOpt = app.add_option("--light", light, "one point light at x,y,z instead of the scene's lights")
      ->check(cli::checked([](const std::string& t) { cli::parseVec3("--light", t); }, "X,Y,Z"));
  app.add_option("--light-color", lightColor, "colour x intensity of --light, r,g,b")
      ->needs(lightOpt)->check(cli::checked([](const std::string& t) { cli::parseColor("--light-color", t); }, "R,G,B"));
  app.add_flag("--falloff", o.lightOptions.falloff, "inverse-square falloff on every light (not the default headlight)");
  app.add_option("--ambient", ambient, "ambient colour r,g,b (or one grey value)")->capture_default_str()
      ->check(cli::checked([](const std::string& t) { cli::parseColor("--ambient", t, true); }, "R,G,B"));
  app.add_flag("!--no-default-light", o.lightOptions.defaultLight,
               "a scene without lights gets no headlight (only ambient and emission light it)");
  app.add_option("--bench", o.bench, "time N frames after 10 warm-up frames; print per-pass GPU min/median")
      ->check(cli::integer(0, 1000000));
  app.add_flag("--watch", o.watch, "recompile edited shaders at run time (windowed)");
  app.add_flag("--orbit", o.orbit, "start in orbit camera mode: left-drag turns about a target, scroll zooms, middle-drag pans (windowed)");
  app.add_option("--device", o.device, "Vulkan device index or name substring (default: discrete GPU first)");
  app.add_flag("--validation", o.validation, "enable the Vulkan validation layer");
  CLI::Option* waitOpt = app.add_flag("--wait-textures,!--no-wait-textures", waitTextures,
               "the first frame waits for the textures (default: yes with --headless; in the window materials show "
               "their factors until their textures are in)");
  app.add_flag("--timings", o.timings, "print the start-up phases in ms, from process start to the first frame (the window's panel shows them too)");
  app.add_flag("!--no-pipeline-cache", o.pipelineCache,
               "neither read nor write the pipeline cache ($XDG_CACHE_HOME/rtr or ~/.cache/rtr; RTR_PIPELINE_CACHE=DIR|off)");
  if (const int rc = cli::parse(app, argc, argv); rc >= 0) return rc;

  try {
    const cli::Size sz = cli::parseSize("--size", size, view::kMaxSize);  // the device's own limit is checked once it is known
    o.width = sz.width;
    o.height = sz.height;
    if (!camera.empty()) o.camera = cli::parsePose("--camera", camera);
    if (!mtl.empty()) o.load.mtl = mtl;
    if (!light.empty()) o.lightOptions.position = cli::parseVec3("--light", light);
    if (!lightColor.empty()) o.lightOptions.color = cli::parseColor("--light-color", lightColor);
    o.lightOptions.ambient = cli::parseColor("--ambient", ambient, true);
    if (o.headless && o.screenshot.empty() && o.bench == 0)
      throw UsageError("--headless needs --screenshot FILE or --bench N: there is nothing to write or measure");
    if (!o.screenshot.empty()) cli::checkImageOutput("--screenshot", o.screenshot, o.force);
    o.mips = cli::enumOption<render::MipMode>("--mips", mips);
    o.mipsGiven = mipsOpt->count() > 0;
    if (waitOpt->count()) o.waitTextures = waitTextures;
    o.shadingGiven = shadingOpt->count() > 0;
    o.settings.mosaic = cli::enumOption<render::MosaicMode>("--mosaic", mosaic);
    o.settings.shading = cli::enumOption<render::ShadingPath>("--shading-path", shadingPath);
    o.settings.sampler.filter = cli::enumOption<render::TextureFilter>("--filter", filter);
    o.settings.raster = cli::enumOption<render::RasterPath>("--raster", raster);
    o.settings.cull = cull == "on";
    return o.headless ? view::runHeadless(o) : view::runWindowed(o);
  } catch (const std::exception& e) {
    return cli::fail("rtr-view", e);
  }
}
