#pragma once
// Writes small glTF test files: binary data appended to buffer 0, bufferViews and accessors listed as
// JSON text, the rest of the document given by the test. As .gltf with an external .bin, .gltf with a
// data-URI buffer, or .glb.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace rtr::test {

inline std::string base64(const std::string& in) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const uint32_t v = uint32_t(uint8_t(in[i])) << 16 | uint32_t(uint8_t(in[i + 1])) << 8 | uint8_t(in[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out += k[(v >> s) & 63];
  }
  if (i < in.size()) {
    const uint32_t v = uint32_t(uint8_t(in[i])) << 16 | (i + 1 < in.size() ? uint32_t(uint8_t(in[i + 1])) << 8 : 0);
    out += k[(v >> 18) & 63];
    out += k[(v >> 12) & 63];
    out += i + 1 < in.size() ? k[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

inline void writeFile(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

inline std::string readFile(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

struct GltfBuilder {
  std::string bin;
  std::vector<std::string> views, accessors;

  // Appends bytes (4-aligned) as a bufferView; `extra` adds JSON members (e.g. "\"byteStride\":12").
  int view(const void* data, size_t n, const std::string& extra = "") {
    bin.append((4 - bin.size() % 4) % 4, '\0');
    const size_t at = bin.size();
    bin.append(static_cast<const char*>(data), n);
    views.push_back("{\"buffer\":0,\"byteOffset\":" + std::to_string(at) + ",\"byteLength\":" + std::to_string(n) +
                    (extra.empty() ? "" : "," + extra) + "}");
    return int(views.size() - 1);
  }
  int accessor(int view, int componentType, size_t count, const std::string& type, const std::string& extra = "") {
    accessors.push_back("{" + (view >= 0 ? "\"bufferView\":" + std::to_string(view) + "," : std::string()) +
                        "\"componentType\":" + std::to_string(componentType) + ",\"count\":" + std::to_string(count) +
                        ",\"type\":\"" + type + "\"" + (extra.empty() ? "" : "," + extra) + "}");
    return int(accessors.size() - 1);
  }
  template <class T>
  int floats(const std::vector<T>& v, const std::string& type) {
    return accessor(view(v.data(), v.size() * sizeof(T)), 5126, v.size(), type);
  }
  int indices(const std::vector<uint32_t>& v) { return accessor(view(v.data(), v.size() * 4), 5125, v.size(), "SCALAR"); }

  // The whole document; `rest` is more top-level members ("\"meshes\":[...],\"nodes\":[...]").
  std::string json(const std::string& rest, const std::string& bufferUri) const {
    std::string s = "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":" + std::to_string(bin.size()) +
                    (bufferUri.empty() ? "" : ",\"uri\":\"" + bufferUri + "\"") + "}]";
    auto list = [&](const char* key, const std::vector<std::string>& v) {
      if (v.empty()) return;
      s += std::string(",\"") + key + "\":[";
      for (size_t i = 0; i < v.size(); ++i) s += (i ? "," : "") + v[i];
      s += "]";
    };
    list("bufferViews", views);
    list("accessors", accessors);
    if (!rest.empty()) s += "," + rest;
    return s + "}";
  }
  std::string glb(const std::string& rest) const {
    std::string j = json(rest, "");
    j.append((4 - j.size() % 4) % 4, ' ');
    std::string b = bin;
    b.append((4 - b.size() % 4) % 4, '\0');
    std::string out;
    auto u32 = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
    out += "glTF";
    u32(2);
    u32(uint32_t(12 + 8 + j.size() + 8 + b.size()));
    u32(uint32_t(j.size()));
    u32(0x4E4F534Au);
    out += j;
    u32(uint32_t(b.size()));
    u32(0x004E4942u);
    out += b;
    return out;
  }
  // Writes dir/name.gltf + dir/name.bin; returns the .gltf path.
  std::filesystem::path writeGltf(const std::filesystem::path& dir, const std::string& name, const std::string& rest) const {
    writeFile(dir / (name + ".bin"), bin);
    writeFile(dir / (name + ".gltf"), json(rest, name + ".bin"));
    return dir / (name + ".gltf");
  }
  std::filesystem::path writeEmbedded(const std::filesystem::path& dir, const std::string& name, const std::string& rest) const {
    writeFile(dir / (name + ".gltf"), json(rest, "data:application/octet-stream;base64," + base64(bin)));
    return dir / (name + ".gltf");
  }
  std::filesystem::path writeGlb(const std::filesystem::path& dir, const std::string& name, const std::string& rest) const {
    writeFile(dir / (name + ".glb"), glb(rest));
    return dir / (name + ".glb");
  }
};

// A fresh folder under the temp dir for one test.
inline std::filesystem::path tempFolder(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("rtr_gltf_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace rtr::test
