#include "scene/load.hpp"

#include <cctype>

#include "core/error.hpp"
#include "scene/clusters.hpp"
#include "scene/course.hpp"
#include "scene/gltf.hpp"
#include "scene/obj.hpp"
#include "scene/rtrscene.hpp"

namespace rtr {

namespace {

Scene loadAny(const std::filesystem::path& file, const LoadOptions& options) {
  const std::string n = file.filename().string();
  auto ends = [&](std::string_view s) { return n.size() >= s.size() && n.compare(n.size() - s.size(), s.size(), s) == 0; };
  if (ends(".obj") || ends(".obj.zst") || ends(".obj-zstd")) {
    ObjOptions o;
    static_cast<LoadOptions&>(o) = options;
    return loadObj(file, o);
  }
  if (options.mtl)
    throw fileError(file.string(), "", "an MTL file ('" + options.mtl->string() + "') can only be given with an OBJ scene");
  if (ends(".comp5892mesh")) return loadCourseMesh(file);
  if (ends(".rtrscene")) return loadRtrScene(file);
  std::string lower = n;
  for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (lower.ends_with(".gltf") || lower.ends_with(".glb")) return loadGltf(file, options);  // as rtr-bake: any case
  throw fileError(file.string(), "",
                  "unknown scene format (expected .obj, .obj.zst, .obj-zstd, .gltf, .glb, .comp5892mesh, .rtrscene)");
}

}  // namespace

Scene loadScene(const std::filesystem::path& file, const LoadOptions& options) {
  Scene scene = stage("reading " + file.string(), [&] { return loadAny(file, options); });
  try {
    // every format but .rtrscene version 3 or later (rtr-bake builds them there)
    stage("clustering", [&] { buildMissingClusters(scene); });
  } catch (const Error& e) { throw fileError(file.string(), "", e.what()); }
  return scene;
}

}  // namespace rtr
