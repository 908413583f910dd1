// Fuzzes rtr-bake's path from OBJ text to a written scene, without files: parse, weld, cluster, encode as
// .rtrscene and decode again. Seeds include the review's OBJ with a vertex at -1e38 (issue 33). Every
// refusal names the OBJ; what is encoded decodes to the same triangle count.
#include <cstdint>
#include <string>

#include "check.hpp"
#include "scene/clusters.hpp"
#include "scene/obj.hpp"
#include "scene/rtrscene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  rtr::ObjOptions opt;
  opt.warn = [](const std::string&) {};
  opt.note = [](const std::string&) {};
  opt.threads = 1;
  rtr::Scene scene;
  try {
    auto src = rtr::memorySource(std::string(reinterpret_cast<const char*>(data), size), "fuzz.obj");
    scene = rtr::parseObj(
        *src, "fuzz.obj", [](const std::string&) { return std::optional<std::string>(); }, opt);
    rtr::buildMissingClusters(scene);
  } catch (const rtr::Error& e) {
    rtr::fuzz::requireNamesFile(e, "fuzz");
    return 0;
  }
  rtr::fuzz::checkScene(scene);
  const std::string bytes = rtr::encodeRtrScene(scene);
  const rtr::Scene back = rtr::decodeRtrScene({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()}, "fuzz.rtrscene");
  rtr::fuzz::checkScene(back);
  size_t a = 0, b = 0;
  for (const rtr::Mesh& m : scene.meshes) a += m.indices.size();
  for (const rtr::Mesh& m : back.meshes) b += m.indices.size();
  rtr::fuzz::require(a == b, "the decoded scene lost triangles");
  return 0;
}
