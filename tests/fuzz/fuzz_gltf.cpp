// Fuzzes the glTF reader (parseGltf, then the clusters loadScene builds): the input is a .gltf (JSON) or,
// when it starts with the GLB magic, a .glb. External URIs resolve in a folder that does not exist, so
// only data URIs and the GLB's BIN chunk carry data. A loaded scene must be usable; a refusal names the file.
#include <cstdint>
#include <span>

#include "check.hpp"
#include "scene/clusters.hpp"
#include "scene/gltf.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rtr;
  const char* name = size >= 4 && std::memcmp(data, "glTF", 4) == 0 ? "fuzz.glb" : "fuzz.gltf";
  LoadOptions o;
  o.note = [](const std::string&) {};
  o.warn = [](const std::string&) {};
  Scene s;
  try {
    s = parseGltf({data, size}, name, "/nonexistent-rtr-fuzz", o);
  } catch (const Error& e) {
    fuzz::requireNamesFile(e, name);
    return 0;
  }
  buildMissingClusters(s);
  fuzz::checkScene(s);
  fuzz::require(!s.instances.empty(), "a loaded glTF scene draws nothing");
  for (const Instance& i : s.instances) fuzz::require(i.mesh < s.meshes.size(), "instance mesh out of range");
  for (const Mesh& m : s.meshes) {
    fuzz::require(m.tangents.empty() || m.tangents.size() == m.positions.size(), "tangent count differs");
    fuzz::require(m.colors.empty() || m.colors.size() == m.positions.size(), "colour count differs");
    fuzz::require(m.texcoords1.empty() || m.texcoords1.size() == m.positions.size(), "texcoord1 count differs");
  }
  for (const Texture& t : s.textures) fuzz::require(t.sourceChannel <= 4, "source channel");
  return 0;
}
