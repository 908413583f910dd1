#include "bake.hpp"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <thread>

#include "core/error.hpp"
#include "core/image.hpp"
#include "scene/binio.hpp"
#include "scene/clusters.hpp"
#include "scene/course.hpp"
#include "scene/first_look.hpp"
#include "scene/rtrscene.hpp"

namespace rtr {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

bool endsWith(const std::string& s, std::string_view e) {
  return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0;
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
void verifyTextures(const TexturePlan& plan, unsigned threads) {
  std::atomic<size_t> next{0};
  std::vector<std::string> errors(plan.sources.size());
  auto work = [&] {
    for (size_t i; (i = next.fetch_add(1)) < plan.sources.size();) {
      const auto& src = plan.sources[i];
      if (src.empty()) continue;
      std::error_code ec;
      if (!std::filesystem::is_regular_file(src, ec)) {
        errors[i] = src.string() + ": texture file named in the MTL does not exist";
        continue;
      }
      try {
        loadImage(src, plan.scene.textures[i].channels);
      } catch (const Error& e) {
        errors[i] = std::string(e.what()) + " (texture named in the MTL is not a readable image)";
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  for (const std::string& e : errors)
    if (!e.empty()) throw Error(e);
}

void writeFallback(const std::filesystem::path& file, const std::string& name, Replace replace) {
  ImageRGBA8 img{1, 1, {255, 255, 255, 255}};
  if (name == kFallbackEmissive) img.pixels = {0, 0, 0, 255};
  saveImage(file, img, {replace});
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
  const unsigned threads = opt.threads ? opt.threads : std::max(1u, std::thread::hardware_concurrency());

  // 1. Parse and weld.
  ObjOptions oo;
  oo.warn = opt.warn;
  oo.threads = threads;
  oo.mtl = opt.mtl;
  oo.creaseDeg = opt.creaseDeg;
  if (opt.progress)
    oo.progress = [&](uint64_t done, uint64_t total) { opt.progress("reading", total ? double(done) / double(total) : 0.0); };
  Scene scene = loadObj(opt.input, oo, &rep.obj);
  turnScene(scene, opt.up);
  rep.parseSeconds = rep.obj.parseSeconds;
  rep.weldSeconds = rep.obj.weldSeconds;
  if (opt.view) scene.defaultView = opt.view;
  if (!opt.lights.empty()) scene.lights = opt.lights;

  // 2. Textures: plan, check every source decodes and no destination would be overwritten, then copy.
  auto t0 = Clock::now();
  std::string sceneName = opt.output.filename().string();
  sceneName = sceneName.substr(0, sceneName.rfind('.'));
  TexturePlan plan = planTextures(scene, sceneName, course);
  scene = Scene{};
  if (opt.progress) opt.progress("checking textures", 0.0);
  verifyTextures(plan, threads);
  const std::filesystem::path texDir = outDir / (sceneName + "-tex");
  for (size_t i = 0; i < plan.scene.textures.size(); ++i) {
    const auto dst = outDir / plan.scene.textures[i].path;
    if (std::filesystem::exists(dst, ec) && !opt.force)
      throw OutputExists(dst.string() + ": texture exists; refusing to overwrite it without --force");
  }
  if (!plan.scene.textures.empty()) createFolders(texDir, created);
  for (size_t i = 0; i < plan.scene.textures.size(); ++i) {
    // Without --force a texture is only ever created, never replaced (FORMATS.md §1): AtomicFile's
    // link-based commit lets exactly one of two concurrent bakes create it; the other stops here.
    const auto dst = outDir / plan.scene.textures[i].path;
    const bool existed = std::filesystem::exists(dst, ec);
    if (plan.sources[i].empty()) {
      writeFallback(dst, dst.filename().string(), replace);
      ++rep.fallbackTextures;
    } else {
      copyFileAtomic(plan.sources[i], dst, replace);
    }
    if (!existed) created.files.push_back(dst);
    if (opt.progress) opt.progress("copying textures", double(i + 1) / double(plan.scene.textures.size()));
  }
  rep.textureSeconds = since(t0);

  // 3. Clusters (.rtrscene stores them; the course format has no place for them, its loader builds them).
  if (!course) {
    t0 = Clock::now();
    if (opt.progress) opt.progress("clustering", 0.0);
    buildMissingClusters(plan.scene);
    rep.clusterSeconds = since(t0);
  }

  // 4. Encode and write (a temporary of our own, then rename; without --force, link, so that an output
  // another run made meanwhile is kept).
  t0 = Clock::now();
  if (opt.progress) opt.progress("writing", 0.0);
  const std::string bytes = course ? encodeCourseMesh(plan.scene) : encodeRtrScene(plan.scene);
  writeFileAtomic(opt.output, bytes, replace);
  created.keep = true;
  rep.writeSeconds = since(t0);
  rep.outputBytes = bytes.size();
  rep.meshes = plan.scene.meshes.size();
  rep.materials = plan.scene.materials.size();
  rep.textures = plan.scene.textures.size() - rep.fallbackTextures;
  rep.totalSeconds = since(start);
  return rep;
}

}  // namespace rtr
