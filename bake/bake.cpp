#include "bake.hpp"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <set>
#include <thread>

#include "core/error.hpp"
#include "core/image.hpp"
#include "scene/binio.hpp"
#include "scene/clusters.hpp"
#include "scene/course.hpp"
#include "scene/load.hpp"
#include "scene/rtrscene.hpp"

namespace rtr {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

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
  std::atomic<size_t> next{0};
  std::vector<std::string> errors(plan.sources.size());
  auto work = [&] {
    for (size_t i; (i = next.fetch_add(1)) < plan.sources.size();) {
      const auto& src = plan.sources[i];
      if (plan.bytes[i]) {
        try {
          decodeImage(*plan.bytes[i], plan.scene.textures[i].path.string(), plan.scene.textures[i].channels);
        } catch (const Error& e) {
          errors[i] = std::string(e.what()) + " (an image embedded in the glTF is not readable)";
        }
      }
      if (src.empty()) continue;
      std::error_code ec;
      if (!std::filesystem::is_regular_file(src, ec)) {
        errors[i] = src.string() + ": texture file named in the " + namedIn + " does not exist";
        continue;
      }
      try {
        loadImage(src, plan.scene.textures[i].channels);
      } catch (const Error& e) {
        errors[i] = std::string(e.what()) + " (texture named in the " + namedIn + " is not a readable image)";
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
  const bool gltf = isGltf(opt.input);
  if (gltf && course)
    throw UsageError(opt.output.string() + ": a glTF bakes to .rtrscene only (the .comp5892mesh format has no instances, "
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
  const unsigned threads = opt.threads ? opt.threads : std::max(1u, std::thread::hardware_concurrency());

  // 1. Parse and weld (OBJ), or read the glTF (instances kept, embedded images held in memory).
  Scene scene;
  if (gltf) {
    if (opt.progress) opt.progress("reading", 0.0);
    LoadOptions lo;
    lo.warn = opt.warn;
    lo.note = opt.note;
    const auto t = Clock::now();
    scene = loadScene(opt.input, lo);
    rep.parseSeconds = since(t);
    rep.gltf = true;
  } else {
    ObjOptions oo;
    oo.warn = opt.warn;
    oo.threads = threads;
    oo.mtl = opt.mtl;
    if (opt.progress)
      oo.progress = [&](uint64_t done, uint64_t total) { opt.progress("reading", total ? double(done) / double(total) : 0.0); };
    scene = loadObj(opt.input, oo, &rep.obj);
    rep.parseSeconds = rep.obj.parseSeconds;
    rep.weldSeconds = rep.obj.weldSeconds;
  }
  for (const Mesh& m : scene.meshes) rep.triangles += m.triangleCount();
  rep.instances = scene.instances.size();
  if (opt.view) scene.defaultView = opt.view;
  if (!opt.lights.empty()) scene.lights = opt.lights;

  // 2. Textures: plan, check every source decodes and no destination would be overwritten, then copy.
  auto t0 = Clock::now();
  std::string sceneName = opt.output.filename().string();
  sceneName = sceneName.substr(0, sceneName.rfind('.'));
  TexturePlan plan = planTextures(scene, sceneName, course);
  scene = Scene{};
  if (opt.progress) opt.progress("checking textures", 0.0);
  verifyTextures(plan, threads, gltf ? "glTF" : "MTL");
  const std::filesystem::path texDir = outDir / (sceneName + "-tex");
  std::vector<bool> present(plan.scene.textures.size());  // an embedded image already there, byte for byte
  for (size_t i = 0; i < plan.scene.textures.size(); ++i) {
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
  if (!plan.scene.textures.empty()) createFolders(texDir, created);
  std::set<std::filesystem::path> written;
  for (size_t i = 0; i < plan.scene.textures.size(); ++i) {
    // Without --force a texture is only ever created, never replaced (FORMATS.md §1): AtomicFile's
    // link-based commit lets exactly one of two concurrent bakes create it; the other stops here.
    const auto dst = outDir / plan.scene.textures[i].path;
    if (present[i] || !written.insert(dst).second) continue;  // one file for textures sampled two ways
    const bool existed = std::filesystem::exists(dst, ec);
    if (plan.bytes[i]) {
      const auto& b = *plan.bytes[i];
      writeFileAtomic(dst, {reinterpret_cast<const char*>(b.data()), b.size()}, Replace::No);
      ++rep.embeddedTextures;
    } else if (plan.sources[i].empty()) {
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
