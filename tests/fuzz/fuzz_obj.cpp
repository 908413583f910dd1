// Fuzzes the OBJ and MTL parsers. The input is "OBJ text \0 MTL text"; every mtllib gets the MTL part.
// With a leading 0x28 0xB5 0x2F 0xFD (the zstd magic) the whole input goes through the stream decoder.
// Each input is parsed as one piece and in tiny pieces on 2 threads, which must agree (docs/obj-mtl.md).
#include <cstdint>
#include <cstring>
#include <string>

#include "check.hpp"
#include "scene/obj.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string in(reinterpret_cast<const char*>(data), size);
  const size_t split = in.find('\0');
  std::string obj = in.substr(0, split);
  std::string mtl = split == std::string::npos ? std::string() : in.substr(split + 1);
  const bool zstd = size >= 4 && std::memcmp(data, "\x28\xB5\x2F\xFD", 4) == 0;
  if (zstd) obj = in;
  // Parsed twice: as one piece, and in pieces of a few bytes on 2 threads (a boundary at nearly every
  // line); the two must agree on the error or on the meshes.
  std::string outcome[2];
  for (int run = 0; run < 2; ++run) {
    rtr::ObjOptions opt;
    opt.warn = [](const std::string&) {};
    opt.note = [](const std::string&) {};
    opt.threads = run == 0 ? 1 : 2;
    opt.pieceBytes = run == 0 ? size_t(1) << 30 : 1 + size % 5;
    std::string lastMtl;  // an error in the MTL part names the MTL
    try {
      auto src = rtr::memorySource(obj, "fuzz.obj", zstd);
      auto readMtl = [&](const std::string& name) {
        lastMtl = name;
        return mtl;
      };
      const rtr::Scene scene = rtr::parseObj(*src, "fuzz.obj", readMtl, opt);
      rtr::fuzz::checkScene(scene);
      for (const rtr::Mesh& m : scene.meshes) {
        outcome[run] += m.name + '\0' + std::to_string(m.material) + '\0';
        outcome[run].append(reinterpret_cast<const char*>(m.positions.data()), m.positions.size() * sizeof(m.positions[0]));
        outcome[run].append(reinterpret_cast<const char*>(m.indices.data()), m.indices.size() * sizeof(m.indices[0]));
      }
    } catch (const rtr::Error& e) {
      if (lastMtl.empty() || !std::strstr(e.what(), lastMtl.c_str())) rtr::fuzz::requireNamesFile(e, "fuzz.obj");
      outcome[run] = std::string("error: ") + e.what();
    }
  }
  rtr::fuzz::require(outcome[0] == outcome[1], "pieces on 2 threads disagree with one piece");
  return 0;
}
