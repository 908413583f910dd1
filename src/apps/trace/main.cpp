// rtr-trace: ray-trace a scene file into an image (the course's ray-tracing part; docs/tracer.md).
#include <algorithm>
#include <cstdio>
#include <cstdint>
#include <exception>
#include <memory>
#include <new>
#include <string>

#include <unistd.h>

#include <CLI/CLI.hpp>

#include "apps/common/cache_options.hpp"
#include "apps/common/environment_options.hpp"
#include "apps/common/light_options.hpp"
#include "core/camera.hpp"
#include "core/cli.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "scene/first_look.hpp"
#include "scene/load.hpp"
#include "trace/tracer.hpp"

namespace {

using namespace rtr;
using namespace rtr::trace;

std::string gStage = "starting";  // what was under way, for an out-of-memory message

int run(int argc, char** argv) {
  CLI::App app{
      "rtr-trace: CPU ray tracer (the GPU's PBR BRDF for models; the course's Blinn-Phong with shadows and "
      "mirrors for the course's scenes)",
      "rtr-trace"};
  std::string scenePath, outPath, size = "1280x720", camera, shading = "auto", shadows = "on", intersectName = "watertight",
                                  mtlPath, up = "+Y", brdf;
  LightOptions lightOptions;
  cli::EnvironmentOptions envOptions;
  TraceSettings s;
  float fov = s.lens.fovYDeg, orthoHeight = 0.0f;
  bool ortho = false, quiet = false, force = false;
  float crease = LoadOptions{}.creaseDeg;
  app.add_option("scene", scenePath, "scene file (.obj, .obj.zst, .comp5892mesh, .rtrscene)")->required();
  app.add_option("mtl,--mtl", mtlPath,
                 "OBJ: its MTL, as the course runs `program NAME.obj NAME.mtl` (default: the "
                 "OBJ's mtllib, else NAME.mtl beside it)");
  app.add_option("-o,--output,--screenshot", outPath, "output image: .png or .jpg (sRGB), .exr or .hdr (linear radiance)")
      ->required();
  app.add_flag("--force", force, "overwrite an existing output");
  app.add_option("--size", size, "image size WxH")
      ->capture_default_str()
      ->check(cli::checked([](const std::string& t) { cli::parseSize("--size", t); }, "WxH"));
  app.add_option(
         "--camera", camera,
         "camera pose x,y,z,yaw,pitch (degrees); default: the scene's stored view, else one that frames the scene (docs/lights.md)")
      ->check(cli::checked([](const std::string& t) { cli::parsePose("--camera", t); }, "X,Y,Z,YAW,PITCH"));
  app.add_option("--fov", fov, "vertical field of view in degrees (the viewer's default; the course uses 80)")
      ->capture_default_str()
      ->check(cli::number(0, 180, true));
  app.add_flag("--ortho", ortho, "orthographic projection (volume ±aspect × ±1, as the course's framework; docs/formats.md)");
  app.add_option("--ortho-height", orthoHeight, "half height of the orthographic volume")->check(cli::number(0, 1e30, true));
  app.add_option("--shading", shading,
                 "auto | phong | pbr | normals | depth; auto (the default): the course's "
                 "Blinn-Phong for the course's own scenes (lit by *light* materials, or using N_mirr/N_ior), else PBR "
                 "as rtr-view shades (docs/viewer.md)")
      ->check(cli::checked(
          [](const std::string& t) {
            if (t != "auto") cli::enumOption<Shading>("--shading", t);
          },
          "{auto|" + enumChoices<Shading>("|") + "}"))
      ->capture_default_str();
  app.add_option("--brdf", brdf,
                 "pbr: beckmann | ggx for every material (default: ggx for glTF materials, "
                 "beckmann for the rest)")
      ->check(cli::oneOf<Brdf>());
  app.add_option("--shadows", shadows, "on | off")->capture_default_str()->check(CLI::IsMember({"on", "off"}));
  app.add_option("--bounces", s.bounces,
                 "mirror bounces, the recursion depth of reflections (the course's N_BOUNCES); "
                 "0 turns reflections off")
      ->capture_default_str()
      ->check(cli::integer(0, 64));
  app.add_option("--threads", s.threads, "worker threads, 0 = every core")->capture_default_str()->check(cli::integer(0, 1024));
  app.add_option("--intersect", intersectName, "halfplane | watertight | moller")
      ->capture_default_str()
      ->check(cli::oneOf<IntersectMethod>());
  app.add_option("--area-samples", s.areaLightSamples, "shadow rays per area light (1: its centre)")
      ->capture_default_str()
      ->check(cli::integer(1, 1024));
  cli::addLightOptions(app, lightOptions);
  app.add_option("--up", up, "the model's up axis, turned to +Y: +X | +Y | +Z | -X | -Y | -Z (a Z-up model: +Z)")
      ->capture_default_str();
  app.add_option("--crease", crease,
                 "OBJ faces without normals: normals split where faces meet at more than DEG "
                 "degrees (0 flat, 180 smooth)")
      ->capture_default_str()
      ->check(cli::number(0, 180));
  cli::addEnvironmentOptions(app, envOptions);
  app.add_option("--spp", s.spp,
                 "pbr with --env: samples per pixel of the environment's light (each a pair: one "
                 "from the environment, one from the BRDF, with a shadow ray each)")
      ->capture_default_str()
      ->check(cli::integer(1, 65536));
  app.add_option("--lod-bias", s.lodBias, "pbr: mipmap LOD bias (as rtr-view's)")
      ->capture_default_str()
      ->check(cli::number(-16, 16));
  app.add_flag("-q,--quiet", quiet, "no progress or summary");
  bool noCache = false;
  cli::addCacheOptions(app, noCache);
  if (const int rc = cli::parse(app, argc, argv); rc >= 0) return rc;

  const cli::Size size2 = cli::parseSize("--size", size);
  const uint32_t w = size2.width, h = size2.height;
  s.width = w;
  s.height = h;
  if (!camera.empty()) s.pose = cli::parsePose("--camera", camera);
  s.lens.fovYDeg = fov;
  s.lens.orthographic = ortho;
  const float aspect = float(w) / float(h);
  s.lens.orthoHalfHeight = orthoHeight > 0.0f ? orthoHeight : (aspect >= 1.0f ? 1.0f : 1.0f / aspect);
  envOptions.resolve();
  // The environment is the light: no headlight and no flat ambient stand in for it unless asked for.
  if (envOptions.hasEnvironment()) lightOptions.defaultLight = false;
  if (envOptions.hasEnvironment() && app.count("--ambient") == 0) lightOptions.ambient = glm::vec3(0.0f);
  s.background = envOptions.backgroundColor;
  s.environmentVisible = envOptions.showEnvironment;
  const glm::mat3 upTurn = upRotation(up);
  if (!brdf.empty()) s.brdf = cli::enumOption<Brdf>("--brdf", brdf);
  s.shadows = shadows == "on";
  s.intersect = cli::enumOption<IntersectMethod>("--intersect", intersectName);
  cli::checkImageOutput("-o", outPath, force);  // before tracing, not after

  gStage = "loading the environment " + envOptions.settings.source;
  s.environment = std::make_shared<const Environment>(Environment::load(envOptions.settings));

  LoadOptions load;
  if (!mtlPath.empty()) load.mtl = mtlPath;
  load.creaseDeg = crease;
  Scene scene = loadScene(scenePath, load);
  turnScene(scene, upTurn);
  drawBothSides(scene);
  // The stored view's field of view (a glTF camera) goes with it, as in rtr-view.
  if (app.count("--fov") == 0 && camera.empty() && scene.defaultView && scene.defaultFovYDeg > 0.0f)
    s.lens.fovYDeg = scene.defaultFovYDeg;
  s.shading = shading != "auto"      ? cli::enumOption<Shading>("--shading", shading)
              : isCourseScene(scene) ? Shading::Phong
                                     : Shading::Pbr;
  if (!quiet && shading == "auto")
    std::fprintf(stderr, "rtr-trace: note: %s shading: %s (--shading)\n", s.shading == Shading::Phong ? "Blinn-Phong" : "PBR",
                 s.shading == Shading::Phong ? "one of the course's scenes" : "a model, shaded as rtr-view shades it");
  if (!quiet && s.environment && !s.environment->empty() && s.shading != Shading::Pbr)
    std::fprintf(stderr,
                 "rtr-trace: note: the environment lights PBR shading only; %s shading sees it where rays "
                 "leave the scene\n",
                 enumName(s.shading));
  s.lights = resolveLights(scene, lightOptions);
  if (envOptions.hasEnvironment() && s.lights->lights.empty() && app.count("--no-default-light") == 0)
    s.lights->note = "lit by the environment (--env: no default headlight, no ambient unless --ambient)";
  if (!quiet && !s.lights->note.empty()) std::fprintf(stderr, "rtr-trace: note: %s\n", s.lights->note.c_str());
  gStage = "building the BVH of " + scenePath;
  const std::unique_ptr<TextureCache> textureCache = cli::textureCache(noCache);
  Tracer tracer(scene, s.threads);
  tracer.setTextureCache(textureCache.get());
  gStage = "tracing " + scenePath + " at " + std::to_string(w) + "x" + std::to_string(h) + " (" +
           std::to_string((uint64_t(w) * h * sizeof(glm::vec4)) >> 20) + " MB of image)";
  const bool tty = !quiet && isatty(STDERR_FILENO);
  ImageF image;
  const RenderStats st = tracer.render(s, image, [&](const TileRect&) {
    if (!tty) return;
    static uint32_t done = 0;
    ++done;
    std::fprintf(stderr, "\rrtr-trace: tracing %3u%%",
                 unsigned(100.0 * done / ((w + s.tileSize - 1) / s.tileSize * ((h + s.tileSize - 1) / s.tileSize))));
  });
  if (tty) std::fprintf(stderr, "\r\033[K");
  const bool lit = std::any_of(image.pixels.begin(), image.pixels.end(), [&](const glm::vec4& p) {
    return glm::vec3(p) != s.background && glm::vec3(p) != glm::vec3(0.0f);
  });
  const std::string empty = emptyImageWarning(scene, tracer.resolvePose(s), s.lens, aspect, lit, s.lights->lights.size());
  if (!empty.empty()) std::fprintf(stderr, "rtr-trace: warning: %s\n", empty.c_str());
  gStage = "writing " + outPath;
  saveImage(outPath, image, {force ? Replace::Yes : Replace::No, !quiet});
  if (!quiet) {
    if (s.shading == Shading::Pbr)
      std::fprintf(stderr,
                   "rtr-trace: %zu textures decoded and mip-mapped in %.3f s (%u from the texture cache); %llu rays "
                   "continued past cut-out texels\n",
                   tracer.textures().count(), tracer.textures().loadSeconds(), tracer.textures().cacheHits(),
                   (unsigned long long)st.alphaRays);
    const uint64_t rays = st.primaryRays + st.shadowRays + st.reflectionRays + st.alphaRays;
    if (st.environmentRays)
      std::fprintf(stderr, "rtr-trace: environment light: %d samples per pixel, %llu shadow rays\n", s.spp,
                   (unsigned long long)st.environmentRays);
    std::fprintf(stderr,
                 "rtr-trace: %zu triangles, %zu lights, %s (build %.3f s); %ux%u in %.3f s: %llu rays "
                 "(%llu primary, %llu shadow, %llu mirror), %.2f Mrays/s; pose %s -> %s\n",
                 tracer.triangles().size(), s.lights->lights.size(),
                 tracer.usesBvh()     ? "BVH8"
                 : tracer.instanced() ? "two-level BVH8"
                                      : "no BVH",
                 tracer.usesBvh() ? tracer.bvh().stats().buildSeconds : 0.0, w, h, st.seconds, (unsigned long long)rays,
                 (unsigned long long)st.primaryRays, (unsigned long long)st.shadowRays, (unsigned long long)st.reflectionRays,
                 double(rays) / st.seconds * 1e-6, formatPose(tracer.resolvePose(s)).c_str(), outPath.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::bad_alloc&) {
    return cli::fail("rtr-trace", Error("out of memory while " + gStage));
  } catch (const std::exception& e) { return cli::fail("rtr-trace", e); }
}
