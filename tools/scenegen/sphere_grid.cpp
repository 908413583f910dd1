#include "sphere_grid.hpp"

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/error.hpp"

namespace scenegen {
namespace {

void append(std::string& bytes, const void* data, size_t size) { bytes.append(static_cast<const char*>(data), size); }

}  // namespace

void writeSphereGrid(const std::filesystem::path& file, int n) {
  if (file.extension() != ".gltf") throw rtr::UsageError("--sphere-grid: '" + file.string() + "' does not end in .gltf");
  if (n < 2 || n > 16) throw rtr::UsageError("--sphere-grid-size: expected 2..16, got " + std::to_string(n));
  // One UV sphere (smooth normals = the unit positions), shared by every mesh; each mesh gives it a material.
  const int slices = 64, stacks = 32;
  const float radius = 0.42f, pi = 3.14159265f;
  std::vector<float> pos, nrm;
  for (int j = 0; j <= stacks; ++j)
    for (int i = 0; i <= slices; ++i) {
      const float theta = pi * float(j) / float(stacks), phi = 2.0f * pi * float(i) / float(slices);
      const float d[3] = {std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)};
      for (float c : d) pos.push_back(radius * c), nrm.push_back(c);
    }
  std::vector<uint32_t> idx;
  auto at = [&](int i, int j) { return uint32_t(j * (slices + 1) + i); };
  for (int j = 0; j < stacks; ++j)
    for (int i = 0; i < slices; ++i) {  // counter-clockwise seen from outside
      // The first uses one vertex of row j, the second two: at a pole row (all one point) that one is empty.
      if (j + 1 < stacks) idx.insert(idx.end(), {at(i, j), at(i, j + 1), at(i + 1, j + 1)});
      if (j > 0) idx.insert(idx.end(), {at(i, j), at(i + 1, j + 1), at(i + 1, j)});
    }
  std::string bin;
  append(bin, pos.data(), pos.size() * 4);
  append(bin, nrm.data(), nrm.size() * 4);
  append(bin, idx.data(), idx.size() * 4);
  const size_t verts = pos.size() / 3, vbytes = pos.size() * 4;

  const std::filesystem::path binFile = std::filesystem::path(file).replace_extension(".bin");
  std::string j = "{\n  \"asset\": {\"version\": \"2.0\", \"generator\": \"rtr scenegen --sphere-grid\"},\n";
  j += "  \"buffers\": [{\"uri\": \"" + binFile.filename().string() + "\", \"byteLength\": " + std::to_string(bin.size()) +
       "}],\n";
  j += "  \"bufferViews\": [\n";
  j += "    {\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": " + std::to_string(vbytes) + ", \"target\": 34962},\n";
  j += "    {\"buffer\": 0, \"byteOffset\": " + std::to_string(vbytes) + ", \"byteLength\": " + std::to_string(vbytes) +
       ", \"target\": 34962},\n";
  j += "    {\"buffer\": 0, \"byteOffset\": " + std::to_string(2 * vbytes) +
       ", \"byteLength\": " + std::to_string(idx.size() * 4) + ", \"target\": 34963}],\n";
  const std::string r = std::to_string(radius);
  j += "  \"accessors\": [\n";
  j += "    {\"bufferView\": 0, \"componentType\": 5126, \"count\": " + std::to_string(verts) +
       ", \"type\": \"VEC3\", \"min\": [-" + r + ", -" + r + ", -" + r + "], \"max\": [" + r + ", " + r + ", " + r + "]},\n";
  j += "    {\"bufferView\": 1, \"componentType\": 5126, \"count\": " + std::to_string(verts) + ", \"type\": \"VEC3\"},\n";
  j +=
      "    {\"bufferView\": 2, \"componentType\": 5125, \"count\": " + std::to_string(idx.size()) + ", \"type\": \"SCALAR\"}],\n";
  std::string materials, meshes, nodes, roots;
  char buf[512];
  for (int row = 0; row < n; ++row)
    for (int c = 0; c < n; ++c) {
      const int k = row * n + c;
      const float metal = float(row) / float(n - 1), rough = float(c) / float(n - 1);
      std::snprintf(buf, sizeof buf,
                    "%s    {\"name\": \"metal%.2f_rough%.2f\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.95, 0.75, "
                    "0.45, 1], \"metallicFactor\": %g, \"roughnessFactor\": %g}}",
                    k ? ",\n" : "", metal, rough, metal, rough);
      materials += buf;
      std::snprintf(buf, sizeof buf,
                    "%s    {\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"NORMAL\": 1}, \"indices\": 2, \"material\": "
                    "%d}]}",
                    k ? ",\n" : "", k);
      meshes += buf;
      std::snprintf(buf, sizeof buf, "%s    {\"name\": \"sphere_%d_%d\", \"mesh\": %d, \"translation\": [%g, %g, 0]}",
                    k ? ",\n" : "", row, c, k, float(c) - 0.5f * float(n - 1), 0.5f * float(n - 1) - float(row));
      nodes += buf;
      roots += (k ? ", " : "") + std::to_string(k);
    }
  j += "  \"materials\": [\n" + materials + "],\n  \"meshes\": [\n" + meshes + "],\n  \"nodes\": [\n" + nodes + "],\n";
  j += "  \"scenes\": [{\"nodes\": [" + roots + "]}],\n  \"scene\": 0\n}\n";
  rtr::writeFileAtomic(binFile, bin);
  rtr::writeFileAtomic(file, j);
}

}  // namespace scenegen
