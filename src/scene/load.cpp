#include "scene/load.hpp"

#include "core/error.hpp"
#include "scene/obj.hpp"

namespace rtr {

Scene loadScene(const std::filesystem::path& file) {
  const std::string n = file.filename().string();
  auto ends = [&](std::string_view s) { return n.size() >= s.size() && n.compare(n.size() - s.size(), s.size(), s) == 0; };
  if (ends(".obj") || ends(".obj.zst") || ends(".obj-zstd")) return loadObj(file);
  throw fileError(file.string(), "", "unknown scene format (expected .obj, .obj.zst, .obj-zstd)");
}

}  // namespace rtr
