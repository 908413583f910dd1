#include "bake.hpp"

#include <unistd.h>

#include <chrono>
#include <cstring>
#include <ctime>
#include <memory>
#include <new>
#include <optional>
#include <set>
#include <system_error>
#include <thread>

#include "core/error.hpp"
#include "core/image.hpp"
#include "core/parallel.hpp"
#include "scene/binio.hpp"
#include "scene/cluster_lod.hpp"
#include "scene/clusters.hpp"
#include "scene/course.hpp"
#include "core/parallel.hpp"
#include "scene/first_look.hpp"
#include "scene/load.hpp"
#include "scene/baked_texels.hpp"
#include "scene/rtrscene.hpp"

namespace rtr {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
double cpuSince(std::clock_t c) { return double(std::clock() - c) / CLOCKS_PER_SEC; }

bool endsWith(const std::string& s, std::string_view e) {
  return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0;
}

bool isGltf(const std::filesystem::path& p) {
  std::string name = p.filename().string();
  for (char& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
  return endsWith(name, ".gltf") || endsWith(name, ".glb");
}

// Removes what it tracked unless told the job succeeded, so a failed bake leaves nothing behind.
struct CreatedFiles {
  std::vector<std::filesystem::path> files;
  bool keep = false;
  ~CreatedFiles() {
    if (keep) return;
    std::error_code ec;
    for (auto it = files.rbegin(); it != files.rend(); ++it) std::filesystem::remove(*it, ec);
  }
};

// Decodes every source texture with the channel count of its slot, on a few threads.
void verifyTextures(const TexturePlan& plan, unsigned threads, const std::string& namedIn) {
  std::vector<std::string> errors(plan.sources.size());
  parallelFor(plan.sources.size(), threads, [&](size_t i) {
    const auto& src = plan.sources[i];
    if (plan.bytes[i]) {
      try {
        decodeImage(*plan.bytes[i], plan.scene.textures[i].path.string(), plan.scene.textures[i].channels);
      } catch (const Error& e) { errors[i] = std::string(e.what()) + " (an image embedded in the glTF is not readable)"; }
    }
    if (src.empty()) return;
    std::error_code ec;
    if (!std::filesystem::exists(src, ec)) {
      errors[i] = src.string() + ": texture file named in the " + namedIn + " does not exist";
      return;
    }
    try {
      loadImage(src, plan.scene.textures[i].channels);
    } catch (const Error& e) {
      errors[i] = std::string(e.what()) + " (texture named in the " + namedIn + " is not a readable image)";
    }
  });
  for (const std::string& e : errors)
    if (!e.empty()) throw Error(e);
}

void writeFallback(AtomicFile& file, const std::string& name) {
  ImageRGBA8 img{1, 1, {255, 255, 255, 255}};
  if (name == kFallbackEmissive) img.pixels = {0, 0, 0, 255};
  writePng(file, img);
}

// Creates `dir` and any missing parents, recording each folder it made.
void createFolders(const std::filesystem::path& dir, CreatedFiles& created) {
  std::error_code ec;
  if (dir.empty() || std::filesystem::is_directory(dir, ec)) return;
  createFolders(dir.parent_path(), created);
  if (std::filesystem::create_directory(dir, ec)) created.files.push_back(dir);
  else if (!std::filesystem::is_directory(dir))  // another bake may have made it meanwhile: fine
    throw fileError(dir.string(), "", "cannot create folder: " + (ec ? ec.message() : "a file of that name exists"));
}

}  // namespace

BakeReport bake(const BakeOptions& opt) {
  const auto start = Clock::now();
  BakeReport rep;
  const std::string out = opt.output.filename().string();
  const bool course = endsWith(out, ".comp5892mesh");
  if (!course && !endsWith(out, ".rtrscene"))
    throw UsageError(opt.output.string() + ": unknown output format (expected .rtrscene or .comp5892mesh)");
  const bool gltf = isGltf(opt.input);
  if (course && opt.textures != TextureStore::Files)
    throw UsageError(opt.output.string() + ": the .comp5892mesh format stores texture files only (--textures files)");
  if (gltf && course)
    throw UsageError(opt.output.string() +
                     ": a glTF bakes to .rtrscene only (the .comp5892mesh format has no instances, "
                     "samplers, uv transforms or glTF materials)");
  std::error_code ec;
  const Replace replace = opt.force ? Replace::Yes : Replace::No;
  if (std::filesystem::exists(opt.output, ec) && !opt.force)
    throw OutputExists(opt.output.string() + ": output exists; use --force to overwrite it");
  std::filesystem::path outDir = opt.output.parent_path();
  if (outDir.empty()) outDir = ".";
  CreatedFiles created;  // removed again if the bake fails
  createFolders(outDir, created);
  if (::access(outDir.c_str(), W_OK) != 0)
    throw fileError(opt.output.string(), "", "output folder '" + outDir.string() + "' is not writable");
  if (opt.view && course && opt.warn) opt.warn("the .comp5892mesh format has no default view; --view ignored");
  if (!opt.lights.empty() && course && opt.warn) opt.warn("the .comp5892mesh format stores no lights; --light ignored");
  const unsigned threads = threadCount(opt.threads);

  // 1. Parse and weld (OBJ), or read the glTF (instances kept, embedded images held in memory).
  auto step = [&](const char* name) {
    if (opt.step) opt.step(name);
  };
  step("parse");
  Scene scene;
  if (gltf) {
    if (opt.progress) opt.progress("reading", 0.0);
    LoadOptions lo;
    lo.warn = opt.warn;
    lo.note = opt.note;
    lo.creaseDeg = opt.creaseDeg;
    const auto t = Clock::now();
    const std::clock_t c = std::clock();
    scene = stage("reading " + opt.input.string(), [&] { return loadScene(opt.input, lo); });
    rep.parseSeconds = since(t);
    rep.parseCpuSeconds = cpuSince(c);
    rep.gltf = true;
  } else {
    ObjOptions oo;
    oo.step = opt.step;
    oo.warn = opt.warn;
    oo.threads = threads;
    oo.mtl = opt.mtl;
    oo.creaseDeg = opt.creaseDeg;
    if (opt.progress) {
      oo.progress = [&](uint64_t done, uint64_t total) { opt.progress("reading", total ? double(done) / double(total) : 0.0); };
      oo.weldProgress = [&](double f) { opt.progress("welding", f); };
    }
    scene = stage("reading " + opt.input.string(), [&] { return loadObj(opt.input, oo, &rep.obj); });
    rep.parseSeconds = rep.obj.parseSeconds;
    rep.weldSeconds = rep.obj.weldSeconds;
    rep.parseCpuSeconds = rep.obj.parseCpuSeconds;
    rep.weldCpuSeconds = rep.obj.weldCpuSeconds;
  }
  turnScene(scene, opt.up);
  for (const Mesh& m : scene.meshes) rep.triangles += m.triangleCount();
  rep.instances = scene.instances.size();
  if (opt.view) scene.defaultView = opt.view;
  if (!opt.lights.empty()) scene.lights = opt.lights;

  // 2. Textures: plan, check every source decodes and no destination would be overwritten, then write
  // each to a temporary beside its destination. They are put in place only once the scene is written too
  // (step 4): a bake that fails anywhere, a full disk included, leaves an older output and its textures
  // as they were.
  const std::string input = opt.input.string();
  step("textures");
  auto t0 = Clock::now();
  std::clock_t c0 = std::clock();
  std::string sceneName = opt.output.filename().string();
  sceneName = sceneName.substr(0, sceneName.rfind('.'));
  TexturePlan plan = planTextures(std::move(scene), sceneName, course);
  const bool baked = opt.textures != TextureStore::Files;
  if (baked) {  // into the file: no texture file is written
    if (opt.progress) opt.progress("baking textures", 0.0);
    stage("baking the textures of " + input, [&] {
      bakeTexels(
          plan, threads, gltf ? "glTF" : "MTL",
          [&](double f) {
            if (opt.progress) opt.progress("baking textures", f);
          },
          opt.textures == TextureStore::Bc, &rep.bcError);
    });
    for (const Texture& t : plan.scene.textures) {
      rep.texelBytes += t.baked->bytes();
      for (const BakedPiece& p : t.baked->pieces) rep.storedTexelBytes += p.stored;
    }
  } else {
    if (opt.progress) opt.progress("checking textures", 0.0);
    stage("checking the textures of " + input, [&] { verifyTextures(plan, threads, gltf ? "glTF" : "MTL"); });
  }
  const std::filesystem::path texDir = outDir / (sceneName + "-tex");
  std::vector<bool> present(plan.scene.textures.size());  // an embedded image already there, byte for byte
  for (size_t i = 0; i < plan.scene.textures.size() && !baked; ++i) {
    const auto dst = outDir / plan.scene.textures[i].path;
    if (!std::filesystem::exists(dst, ec)) continue;
    if (plan.bytes[i]) {  // named by its content: the same bytes are kept, other bytes are never replaced
      present[i] = std::filesystem::is_regular_file(dst, ec) && readFileBytes(dst) == *plan.bytes[i];
      if (!present[i])
        throw OutputExists(dst.string() + ": a different file has the name of an embedded image; refusing to overwrite it");
    } else if (!opt.force) {
      throw OutputExists(dst.string() + ": texture exists; refusing to overwrite it without --force");
    }
  }
  if (!plan.scene.textures.empty() && !baked) createFolders(texDir, created);
  std::set<std::filesystem::path> written;
  std::vector<std::unique_ptr<AtomicFile>> textures;
  std::vector<Replace> textureReplace;
  for (size_t i = 0; i < plan.scene.textures.size() && !baked; ++i) {
    const auto dst = outDir / plan.scene.textures[i].path;
    if (present[i] || !written.insert(dst).second) continue;  // one file for textures sampled two ways
    textures.push_back(std::make_unique<AtomicFile>(dst));
    if (plan.bytes[i]) {  // named by its content: never replaces another file
      const auto& b = *plan.bytes[i];
      textures.back()->write(b.data(), b.size());
      textureReplace.push_back(Replace::No);
      ++rep.embeddedTextures;
    } else if (plan.sources[i].empty()) {
      writeFallback(*textures.back(), dst.filename().string());
      textureReplace.push_back(replace);
      ++rep.fallbackTextures;
    } else {
      textures.back()->writeFrom(plan.sources[i]);
      textureReplace.push_back(replace);
    }
    textures.back()->sync();  // closed: a scene of thousands of textures holds no descriptor for each
    if (opt.progress) opt.progress("copying textures", double(i + 1) / double(plan.scene.textures.size()));
  }
  rep.textureSeconds = since(t0);
  rep.textureCpuSeconds = cpuSince(c0);

  // 3. Clusters (.rtrscene stores them; the course format has no place for them, its loader builds them),
  // and the hierarchy over them (docs/virtual-geometry.md), on all cores. An .rtrscene is written beside
  // them by a thread of its own: what comes before a mesh's indices in the file is final already, and
  // its indices and clusters are written as the build makes them final, piece by piece (ClusterProgress).
  AtomicFile sceneFile(opt.output);
  std::optional<ClusterProgress> built;
  std::exception_ptr writeFailed;
  Clock::time_point writerEnd;
  std::jthread writer;  // declared last: joined first if anything below throws
  if (!course) {
    built.emplace(plan.scene);
    writer = std::jthread([&] {
      try {
        rep.outputBytes = stage("writing " + opt.output.string(), [&] {
          return writeRtrScene(plan.scene, sceneFile, threads, size_t(64) << 20,
                               [&](size_t mesh, size_t triangles) { built->wait(mesh, triangles); });
        });
      } catch (...) { writeFailed = std::current_exception(); }
      writerEnd = Clock::now();
    });
    try {
      t0 = Clock::now();
      c0 = std::clock();
      if (opt.progress) opt.progress("clustering", 0.0);
      step("clusters");
      try {
        stage("clustering " + input, [&] { buildMissingClusters(plan.scene, threads, &*built); });
      } catch (const Error& e) { throw fileError(input, "", e.what()); }
      rep.clusterSeconds = since(t0);
      rep.clusterCpuSeconds = cpuSince(c0);
      if (opt.lod) {
        t0 = Clock::now();
        c0 = std::clock();
        if (opt.progress) opt.progress("cluster hierarchy", 0.0);
        step("hierarchy");
        try {
          stage("cluster hierarchy of " + input, [&] { buildMissingClusterLods(plan.scene, threads); });
        } catch (const Error& e) { throw fileError(input, "", e.what()); }
        rep.lodSeconds = since(t0);
        rep.lodCpuSeconds = cpuSince(c0);
      }
      built->finish();
    } catch (...) {
      built->stop();  // the writer stops too; the build's error is the one reported
      throw;
    }
  }

  // 4. The write's rest (the course format: all of it), then the textures and the scene put in place.
  // Without --force each goes in by link, so that an output another run made meanwhile is kept (and this
  // run's textures already placed are removed again).
  t0 = Clock::now();
  c0 = std::clock();
  if (opt.progress) opt.progress("writing", 0.0);
  step("write");
  if (course) {
    const std::string bytes = stage("encoding " + opt.output.string(), [&] { return encodeCourseMesh(plan.scene); });
    rep.encodeSeconds = since(t0);
    sceneFile.write(bytes.data(), bytes.size());
    rep.outputBytes = bytes.size();
    rep.fileWriteSeconds = since(t0) - rep.encodeSeconds;
  } else {
    writer.join();
    if (writeFailed) std::rethrow_exception(writeFailed);
    rep.fileWriteSeconds = std::max(0.0, std::chrono::duration<double>(writerEnd - t0).count());
  }
  sceneFile.sync();
  for (size_t k = 0; k < textures.size(); ++k) {
    const bool existed = std::filesystem::exists(textures[k]->target(), ec);
    textures[k]->commit(textureReplace[k]);
    if (!existed) created.files.push_back(textures[k]->target());
  }
  sceneFile.commit(replace);
  created.keep = true;
  rep.writeSeconds = since(t0);
  rep.writeCpuSeconds = cpuSince(c0);
  rep.meshes = plan.scene.meshes.size();
  rep.materials = plan.scene.materials.size();
  rep.textures = plan.scene.textures.size() - rep.fallbackTextures;
  rep.totalSeconds = since(start);
  return rep;
}

}  // namespace rtr
