// Fuzzes the OBJ and MTL parsers. The input is "OBJ text \0 MTL text"; every mtllib gets the MTL part.
// With a leading 0x28 0xB5 0x2F 0xFD (the zstd magic) the OBJ part goes through the stream decoder.
#include <cstdint>
#include <cstring>
#include <string>

#include "core/error.hpp"
#include "scene/obj.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string in(reinterpret_cast<const char*>(data), size);
  const size_t split = in.find('\0');
  std::string obj = in.substr(0, split);
  std::string mtl = split == std::string::npos ? std::string() : in.substr(split + 1);
  const bool zstd = size >= 4 && std::memcmp(data, "\x28\xB5\x2F\xFD", 4) == 0;
  if (zstd) obj = in;  // the whole input is the compressed stream
  rtr::ObjOptions opt;
  opt.warn = [](const std::string&) {};
  opt.threads = 1;
  try {
    auto src = rtr::memorySource(obj, "fuzz.obj", zstd);
    rtr::Scene s = rtr::parseObj(*src, "fuzz.obj", [&](const std::string&) { return mtl; }, opt);
    for (const rtr::Mesh& m : s.meshes)
      for (uint32_t i : m.indices)
        if (i >= m.positions.size() || m.material >= s.materials.size()) __builtin_trap();
  } catch (const rtr::Error&) {
  }
  return 0;
}
