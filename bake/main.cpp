// rtr-bake INPUT OUTPUT [--force] [--view x,y,z,yaw,pitch] [--light x,y,z]: OBJ (plain or zstd) + MTL to
// .rtrscene / .comp5892mesh, glTF (.gltf, .glb) to .rtrscene.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <string>
#include <vector>
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>

#include "bake.hpp"
#include "cores.hpp"
#include "core/cli.hpp"
#include "core/error.hpp"
#include "core/parallel.hpp"
#include "scene/first_look.hpp"

namespace {

// --profile: each phase (its steps summed), then each step, in the order they first ran.
void printCores(const std::vector<rtr::CoreUse>& use, unsigned threads) {
  std::vector<rtr::CoreUse> phases;
  for (const rtr::CoreUse& u : use) {
    const std::string phase = u.step.substr(0, u.step.find(':'));
    auto it = std::find_if(phases.begin(), phases.end(), [&](const rtr::CoreUse& p) { return p.step == phase; });
    if (it == phases.end()) it = phases.insert(phases.end(), rtr::CoreUse{phase});
    it->wall += u.wall, it->cpu += u.cpu, it->notAll += u.notAll, it->oneOrNone += u.oneOrNone, it->idle += u.idle;
  }
  std::printf("  cores busy of %u (sampled every 2 ms; wall s with fewer than all busy / with at most one; core-s idle):\n",
              threads);
  auto line = [](const char* indent, const rtr::CoreUse& u) {
    std::printf("%s%-44s %8.3f s wall %6.2f cores  not all busy %7.3f  at most one %7.3f  idle %8.3f\n", indent, u.step.c_str(),
                u.wall, u.cores(), u.notAll, u.oneOrNone, u.idle);
  };
  for (const rtr::CoreUse& p : phases) line("    ", p);
  for (const rtr::CoreUse& u : use)
    if (u.step.find(':') != std::string::npos) line("      ", u);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Bakes an OBJ (.obj, .obj.zst, .obj-zstd) and its MTL into .rtrscene or .comp5892mesh, or a glTF 2.0 "
      "scene (.gltf, .glb) into .rtrscene",
      "rtr-bake"};
  rtr::BakeOptions opt;
  std::string input, output, view, light, lightColor, mtl;
  app.add_option("INPUT", input, "OBJ or glTF file")->required();
  app.add_option("OUTPUT", output, "output file (.rtrscene or .comp5892mesh); a missing folder is created")->required();
  app.add_option("--mtl", mtl, "take the materials from this MTL (default: the OBJ's mtllib, else NAME.mtl beside it)");
  app.add_flag("--force", opt.force, "overwrite an existing output and textures");
  using rtr::cli::checked;
  app.add_option("--view", view, "default camera pose x,y,z,yaw,pitch (degrees)")
      ->check(checked([](const std::string& t) { rtr::cli::parsePose("--view", t); }, "X,Y,Z,YAW,PITCH"));
  CLI::Option* lightOpt =
      app.add_option("--light", light, "store a point light at x,y,z with the scene (.rtrscene); it replaces the scene's own")
          ->check(checked([](const std::string& t) { rtr::cli::parseVec3("--light", t); }, "X,Y,Z"));
  app.add_option("--light-color", lightColor, "colour x intensity of --light, r,g,b")
      ->needs(lightOpt)
      ->check(checked([](const std::string& t) { rtr::cli::parseColor("--light-color", t); }, "R,G,B"));
  bool noLod = false;
  app.add_flag("--no-lod", noLod, "store no cluster hierarchy (level of detail; docs/virtual-geometry.md)");
  bool progress = false;
  app.add_flag("--progress", progress, "show the progress line on stderr also when it is not a terminal");
  bool profile = false;
  app.add_flag("--profile", profile,
               "after the summary, the cores each phase and step kept busy (sampled every 2 ms): where the "
               "wall time passed with fewer than all threads busy");
  app.add_option("--threads", opt.threads, "worker threads (0: all cores)")->check(rtr::cli::integer(0, 1024));
  std::string up = "+Y";
  app.add_option("--up", up, "the model's up axis, turned to +Y: +X | +Y | +Z | -X | -Y | -Z (a Z-up model: +Z)")
      ->capture_default_str();
  app.add_option("--crease", opt.creaseDeg,
                 "faces without normals: normals split where faces meet at more than DEG "
                 "degrees (0 flat, 180 smooth)")
      ->capture_default_str()
      ->check(rtr::cli::number(0, 180));
  std::string textures = "files";
  app.add_option("--textures", textures,
                 "how an .rtrscene carries its textures: files (image files in NAME-tex/, "
                 "decoded at load) | lossless (the mip chains as the GPU samples them, zstd, in the file) | bc (the same, "
                 "block-compressed: BC1/BC3/BC4; prints the error against lossless per level)")
      ->check(rtr::cli::oneOf<rtr::TextureStore>())
      ->capture_default_str();
  if (const int rc = rtr::cli::parse(app, argc, argv); rc >= 0) return rc;
  opt.textures = rtr::cli::enumOption<rtr::TextureStore>("--textures", textures);
  opt.lod = !noLod;

  opt.input = input;
  opt.output = output;
  opt.warn = [](const std::string& w) { std::cerr << "\rwarning: " << w << "\n"; };
  opt.note = [](const std::string& n) { std::cerr << "\rnote: " << n << "\n"; };
  // The progress line: on a terminal, or when asked (a log of a long bake); one line, rewritten.
  const bool tty = ::isatty(2) || progress;
  const auto started = std::chrono::steady_clock::now();
  if (tty)
    opt.progress = [started](const char* phase, double f) {
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      std::fprintf(stderr, "\r%-18s %5.1f%%  %7.1f s", phase, f * 100.0, s);
      std::fflush(stderr);
    };
  try {
    if (!view.empty()) opt.view = rtr::cli::parsePose("--view", view);
    if (!mtl.empty()) opt.mtl = mtl;
    opt.up = rtr::upRotation(up);
    if (!light.empty()) {
      rtr::Light l;
      l.position = rtr::cli::parseVec3("--light", light);
      if (!lightColor.empty()) l.color = rtr::cli::parseColor("--light-color", lightColor);
      opt.lights = {l};
    }
    std::optional<rtr::CoreSampler> sampler;
    if (profile) {
      sampler.emplace(rtr::threadCount(opt.threads));
      opt.step = [&](const char* step) { sampler->mark(step); };
    }
    const rtr::BakeReport r = rtr::bake(opt);
    const std::vector<rtr::CoreUse> use = sampler ? sampler->stop() : std::vector<rtr::CoreUse>();
    if (tty) std::fprintf(stderr, "\r%40s\r", "");  // the progress line cleared
    const auto& o = r.obj;
    const double mb = double(o.textBytes) / 1e6;
    std::printf("%s -> %s\n", input.c_str(), output.c_str());
    if (r.texelBytes)
      std::printf("  textures baked: %.2f MB of mip chains, %.2f MB stored\n", double(r.texelBytes) / 1e6,
                  double(r.storedTexelBytes) / 1e6);
    for (size_t l = 0; l < r.bcError.size(); ++l)
      std::printf("  BC error vs lossless, level %2zu: mean %.3f LSB, max %d LSB (%llu samples)\n", l,
                  r.bcError[l].samples ? r.bcError[l].sumAbs / double(r.bcError[l].samples) : 0.0, r.bcError[l].max,
                  static_cast<unsigned long long>(r.bcError[l].samples));
    if (r.gltf) {
      std::printf("  meshes %zu, instances %zu, materials %zu, textures %zu (%zu images written from the glTF)\n", r.meshes,
                  r.instances, r.materials, r.textures, r.embeddedTextures);
      std::printf("  triangles %zu, output %.2f MB\n", r.triangles, double(r.outputBytes) / 1e6);
      std::printf("  time: read %.3f s, textures %.3f s, clusters %.3f s, hierarchy %.3f s, write %.3f s, total %.3f s\n",
                  r.parseSeconds, r.textureSeconds, r.clusterSeconds, r.lodSeconds, r.writeSeconds, r.totalSeconds);
      return 0;
    }
    std::printf("  meshes %zu, materials %zu, textures %zu (+%zu fallback)\n", r.meshes, r.materials, r.textures,
                r.fallbackTextures);
    std::printf("  faces %zu, triangles %zu, degenerate skipped %zu\n", o.faces, o.triangles, o.degenerateSkipped);
    std::printf("  vertices %zu before welding, %zu after\n", o.verticesBeforeWeld, o.verticesAfterWeld);
    std::printf("  warnings %zu, output %.2f MB\n", o.warnings, double(r.outputBytes) / 1e6);
    std::printf(
        "  time: parse %.3f s (%.0f MB/s of OBJ text, %u threads, %.3f s of it waiting for the text), weld %.3f s, textures %.3f s, clusters %.3f s, hierarchy %.3f s, write %.3f s (made and written %.3f, sync %.3f), total %.3f s\n",
        r.parseSeconds, r.parseSeconds > 0 ? mb / r.parseSeconds : 0.0, rtr::threadCount(opt.threads), o.textWaitSeconds,
        r.weldSeconds, r.textureSeconds, r.clusterSeconds, r.lodSeconds, r.writeSeconds, r.encodeSeconds + r.fileWriteSeconds,
        r.writeSeconds - r.encodeSeconds - r.fileWriteSeconds, r.totalSeconds);
    std::printf(
        "  cpu (all threads): parse %.3f s, weld %.3f s, textures %.3f s, clusters %.3f s, hierarchy %.3f s, write %.3f s\n",
        r.parseCpuSeconds, r.weldCpuSeconds, r.textureCpuSeconds, r.clusterCpuSeconds, r.lodCpuSeconds, r.writeCpuSeconds);
    if (sampler) printCores(use, sampler->threads());
    return 0;
  } catch (const std::exception& e) {
    if (tty) std::fprintf(stderr, "\n");
    return rtr::cli::fail("rtr-bake", e);
  }
}
