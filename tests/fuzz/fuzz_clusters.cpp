// Fuzzes the loader's clustering with any float a reader could let through: the input is read as
// positions (3 little-endian floats each, every value meshoptimizer could meet: NaN, infinities, ±1e38,
// denormals) followed by indices. buildClusters must refuse what meshoptimizer would assert on (issue 33:
// a vertex at -1e38 aborted every tool) and otherwise keep every triangle in finite clusters.
#include <cstdint>
#include <cstring>

#include "check.hpp"
#include "scene/clusters.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 2) return 0;
  const size_t vertices = std::min<size_t>(data[0] + 1, (size - 2) / 12);  // the first byte: how many
  const bool cones = data[1] & 1;
  data += 2, size -= 2;
  if (vertices == 0) return 0;
  rtr::Mesh m;
  m.name = "fuzz";
  m.positions.resize(vertices);
  std::memcpy(m.positions.writable().data(), data, vertices * 12);
  data += vertices * 12, size -= vertices * 12;
  for (size_t i = 0; i + 3 <= size && m.indices.size() < 3 * 2048; i += 3)  // one byte an index, some out of range
    for (int k = 0; k < 3; ++k) m.indices.push_back(data[i + k] % (vertices + 2));
  m.normals.assign(vertices, glm::vec3(0, 0, 1));
  try {
    rtr::buildClusters(m, cones);
  } catch (const rtr::Error& e) {
    rtr::fuzz::requireNamesFile(e, "mesh 'fuzz'");
    return 0;
  }
  rtr::Scene s;
  s.materials.emplace_back();
  s.meshes.push_back(std::move(m));
  rtr::fuzz::checkScene(s);
  return 0;
}
