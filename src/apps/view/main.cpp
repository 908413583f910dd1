// rtr-view: the Vulkan viewer. Headless (--headless: no window, no display) or in a GLFW window.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <future>
#include <optional>
#include <iostream>
#include <map>

#include <unistd.h>

#include <CLI/CLI.hpp>

#include "core/cli.hpp"
#include "core/error.hpp"
#include "options.hpp"
#include "view_state.hpp"
#include "render/headless.hpp"
#include "render/startup.hpp"
#include "scene/first_look.hpp"
#include "scene/framing.hpp"
#include "scene/load.hpp"
#include "vk/context.hpp"
#include "vk/pipeline_cache.hpp"

namespace rtr::view {

Scene loadForView(const ViewOptions& o, const std::string& path) {
  Scene scene = loadScene(path, o.load);
  turnScene(scene, o.up);
  drawBothSides(scene);
  return scene;
}

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
               render::toString(c.shading), o.shadingGiven ? "--shading-path" : "default",
               render::toString(c.mips), o.mipsGiven ? "--mips" : "default");
  if (!o.shadingGiven || !o.mipsGiven) std::fprintf(stderr, ": the defaults for %s (docs/startup.md)", d.why);
  std::fprintf(stderr, "\n");
  if (const float max = render::maxAnisotropy(ctx); o.settings.sampler.anisotropy > max)
    std::fprintf(stderr, "rtr-view: note: --anisotropy %g: %s samples with at most %g\n", o.settings.sampler.anisotropy,
                 ctx.deviceName().c_str(), max);
  return c;
}

std::vector<std::string> sceneFiles(const std::vector<std::string>& given) {
  auto isScene = [](const std::string& n) {
    for (std::string_view e : {".obj", ".obj.zst", ".obj-zstd", ".rtrscene", ".comp5892mesh", ".gltf", ".glb"})
      if (n.size() > e.size() && n.compare(n.size() - e.size(), e.size(), e) == 0) return true;
    return false;
  };
  std::vector<std::string> files;
  for (const std::string& g : given) {
    std::error_code ec;
    if (!std::filesystem::is_directory(g, ec)) {
      files.push_back(g);
      continue;
    }
    std::vector<std::string> inside;
    for (const auto& e : std::filesystem::directory_iterator(g, ec))
      if (e.is_regular_file(ec) && isScene(e.path().filename().string())) inside.push_back(e.path().string());
    if (inside.empty()) throw UsageError("'" + g + "': a folder without scene files (.obj, .rtrscene, ...)");
    std::sort(inside.begin(), inside.end());
    files.insert(files.end(), inside.begin(), inside.end());
  }
  return files;
}

namespace {

bool anyLit(const ImageRGBA8& img) {  // the background is black
  for (size_t i = 0; i < img.pixels.size(); i += 4)
    if (img.pixels[i] | img.pixels[i + 1] | img.pixels[i + 2]) return true;
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
  Scene scene = loadForView(o, o.scene);
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
    const std::string empty = emptyImageWarning(scene, pose, lens, float(o.width) / float(o.height), anyLit(frame.image),
                                                settings.lights.lights.size());
    if (!empty.empty()) std::fprintf(stderr, "rtr-view: warning: %s\n", empty.c_str());
    // Compressed on all cores while the renderer, the scene and the device are torn down (10-15 ms on
    // lavapipe, about a third of the PNG's time there).
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
  const int status = renderHeadless(o, writing);
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
  std::string description = "rtr-view: real-time Vulkan viewer (PBR, alpha masking, compute mosaic, debug views).\n"
                            "Keys in the window (the panel's Keys section; docs/viewer.md):\n";
  for (const auto& [key, what] : view::keyList()) description += "  " + std::string(key) + ": " + what + "\n";
  description += "View 13 (albedo) has no key: --mode 13 or the panel.";
  CLI::App app{description,
               "rtr-view"};
  std::string camera, size = "1280x720", mips = "compute", mosaic = "off", light, lightColor,
              ambient = "0.02", mtl,
              filter = "trilinear";
  bool waitTextures = true;
  std::string shadingPath = render::toString(o.settings.shading), raster = render::toString(o.settings.raster);
  std::vector<std::string> given;
  app.add_option("scene", given, "scene files (.rtrscene, .comp5892mesh, .obj, .obj.zst) or folders of them; the window "
                 "shows the first, Left/Right the others (--headless: one file)")->required();
  app.add_option("--mtl", mtl, "OBJ: take the materials from this MTL (default: the OBJ's mtllib, else NAME.mtl beside it)");
  app.add_flag("--headless", o.headless, "render offscreen: no window, no display needed");
  app.add_option("--size", size, "image size WxH")->capture_default_str();
  app.add_option("--camera", camera, "start pose x,y,z,yaw,pitch (degrees)");
  app.add_option("--fov", o.lens.fovYDeg, "vertical field of view in degrees")->capture_default_str()
      ->check(cli::number(0, 180, true));
  app.add_option("--mode", o.settings.mode, "view mode 1-13: 1 shaded, 2 mip level, 3 linear depth, 4 depth derivatives, "
                 "5 normal, 6 view dir, 7 light dir, 8 BRDF D, 9 BRDF F, 10 BRDF G, 11 diffuse, 12 specular, 13 albedo")->check(CLI::Range(1, VIEW_COUNT))->capture_default_str();
  app.add_option("--frames", o.frames, "frames to render before the screenshot")->check(cli::integer(1, 100000));
  app.add_option("-o,--output,--screenshot", o.screenshot,
                 "write the rendered frame (not the overlay): .png, .jpg, .exr or .hdr");
  app.add_flag("--force", o.force, "overwrite an existing screenshot");
  CLI::Option* mipsOpt = app.add_option("--mips", mips, "mip generation: compute (several levels per dispatch) | blit | auto (per texture: compute "
                                        "when small, blit when large) "
                                        "(default: the device's fastest, docs/startup.md)");
  app.add_option("--mosaic", mosaic, "post process: off (the scene plainly) | compute | graphics (the 5x3 mosaic "
                 "filter the course's assignment asks for, in a compute or a graphics pass)")->capture_default_str();
  CLI::Option* shadingOpt =
      app.add_option("--shading-path", shadingPath, "shaded view: visibility (ids rasterised, BRDF in compute) | forward "
                     "(default: the device's fastest, docs/startup.md)")
          ->check(CLI::IsMember({"visibility", "forward"}));
  app.add_option("--raster", raster, "visibility ids: hardware | compute (64-bit atomics) | auto (the device's default)")
      ->check(CLI::IsMember({"auto", "hardware", "compute"}))->capture_default_str();
  std::string cull = "off";
  app.add_option("--cull", cull, "compute raster: two-phase cluster culling (frustum, back-face cones, depth pyramid) on | off")
      ->check(CLI::IsMember({"on", "off"}))->capture_default_str();
  app.add_option("--lod-bias", o.settings.lodBias, "mipmap LOD bias")->check(cli::number(-16, 16));
  app.add_option("--filter", filter, "texture filter: trilinear | nearest-mip (nearest level, bilinear in it) | nearest "
                 "(nearest texel of the nearest level)")
      ->check(CLI::IsMember({"trilinear", "nearest-mip", "nearest"}))->capture_default_str();
  app.add_option("--anisotropy", o.settings.sampler.anisotropy,
                 "anisotropic filtering, 1 (off) up to the device's maxSamplerAnisotropy (more is clamped, with a note)")
      ->check(cli::number(1, 64))->capture_default_str();
  app.add_option("--light", light, "one point light at x,y,z instead of the scene's lights");
  app.add_option("--light-color", lightColor, "colour x intensity of --light, r,g,b");
  app.add_flag("--falloff", o.lightOptions.falloff, "inverse-square falloff on every light (not the default headlight)");
  app.add_option("--ambient", ambient, "ambient colour r,g,b (or one grey value)")->capture_default_str();
  bool noDefaultLight = false, noPipelineCache = false, noWaitTextures = false;
  std::string up = "+Y";
  app.add_flag("--no-default-light", noDefaultLight,
               "a scene without lights gets no headlight (only ambient and emission light it)");
  app.add_option("--up", up, "the model's up axis, turned to +Y: +X | +Y | +Z | -X | -Y | -Z (a Z-up model: +Z)")
      ->capture_default_str();
  app.add_option("--crease", o.load.creaseDeg, "OBJ faces without normals: normals split where faces meet at more "
                 "than DEG degrees (0 flat, 180 smooth)")->capture_default_str()->check(cli::number(0, 180));
  app.add_option("--bench", o.bench, "time N frames after 10 warm-up frames; print per-pass GPU min/median")
      ->check(cli::integer(0, 1000000));
  app.add_flag("--watch", o.watch, "recompile edited shaders at run time (windowed)");
  app.add_flag("--orbit", o.orbit, "start in orbit camera mode: left-drag turns about a target, scroll zooms, middle-drag pans (windowed)");
  app.add_option("--device", o.device, "Vulkan device index or name substring (default: discrete GPU first)");
  app.add_flag("--validation", o.validation, "enable the Vulkan validation layer");
  CLI::Option* waitOpt = app.add_flag("--wait-textures", waitTextures,
               "the first frame waits for the textures (default: yes with --headless; in the window materials show "
               "their factors until their textures are in)");
  app.add_flag("--no-wait-textures", noWaitTextures, "the first frame shows the materials' factors; textures come later")
      ->excludes(waitOpt);
  app.add_flag("--timings", o.timings, "print the start-up phases in ms, from process start to the first frame (the window's panel shows them too)");
  app.add_flag("--no-pipeline-cache", noPipelineCache,
               "neither read nor write the pipeline cache ($XDG_CACHE_HOME/rtr or ~/.cache/rtr; RTR_PIPELINE_CACHE=DIR|off)");
  // Test-only seams of the window (tests/view/panel_test.py), hidden from --help.
  app.add_flag("--test-ui", o.testUi)->group("");
  app.add_option("--test-drop", o.testDropFile)->group("");
  if (const int rc = cli::parse(app, argc, argv); rc >= 0) return rc;

  try {
    o.files = view::sceneFiles(given);
    o.scene = o.files.front();
    if (o.headless && o.files.size() > 1)
      throw UsageError("--headless renders one scene file; " + std::to_string(o.files.size()) + " given");
    const cli::Size sz = cli::parseSize("--size", size, view::kMaxSize);  // the device's own limit is checked once it is known
    o.width = sz.width;
    o.height = sz.height;
    if (!camera.empty()) o.camera = cli::parsePose("--camera", camera);
    if (!mtl.empty()) o.load.mtl = mtl;
    o.up = upRotation(up);
    o.lightOptions.defaultLight = !noDefaultLight;
    o.pipelineCache = !noPipelineCache;
    if (!light.empty()) o.lightOptions.position = cli::parseVec3("--light", light);
    if (!lightColor.empty()) o.lightOptions.color = cli::parseVec3("--light-color", lightColor);
    o.lightOptions.ambient = cli::parseVec3("--ambient", ambient, true);
    if (o.headless && o.screenshot.empty() && o.bench == 0)
      throw UsageError("--headless needs --screenshot FILE or --bench N: there is nothing to write or measure");
    if (!o.screenshot.empty()) cli::checkImageOutput("--screenshot", o.screenshot, o.force);
    const std::map<std::string, render::MipMode> mipModes{{"compute", render::MipMode::Compute},
                                                          {"blit", render::MipMode::Blit},
                                                          {"auto", render::MipMode::Auto}};
    const std::map<std::string, render::MosaicMode> mosaicModes{
        {"off", render::MosaicMode::Off}, {"compute", render::MosaicMode::Compute}, {"graphics", render::MosaicMode::Graphics}};
    if (!mipModes.count(mips)) throw UsageError("--mips '" + mips + "': expected compute, blit or auto");
    if (!mosaicModes.count(mosaic)) throw UsageError("--mosaic '" + mosaic + "': expected off, compute or graphics");
    o.mips = mipModes.at(mips);
    o.mipsGiven = mipsOpt->count() > 0;
    if (waitOpt->count()) o.waitTextures = true;
    if (noWaitTextures) o.waitTextures = false;
    o.shadingGiven = shadingOpt->count() > 0;
    o.settings.mosaic = mosaicModes.at(mosaic);
    o.settings.shading = shadingPath == "forward" ? render::ShadingPath::Forward : render::ShadingPath::Visibility;
    o.settings.sampler.filter = filter == "nearest" ? render::TextureFilter::Nearest
                                : filter == "nearest-mip" ? render::TextureFilter::NearestMip
                                                          : render::TextureFilter::Trilinear;
    o.settings.raster = raster == "hardware" ? render::RasterPath::Hardware
                        : raster == "compute" ? render::RasterPath::Compute
                                              : render::RasterPath::Auto;
    o.settings.cull = cull == "on";
    return o.headless ? view::runHeadless(o) : view::runWindowed(o);
  } catch (const std::exception& e) {
    return cli::fail("rtr-view", e);
  }
}
