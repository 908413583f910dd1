// Fuzzes the OBJ and MTL parsers. The input is "OBJ text \0 MTL text"; every mtllib gets the MTL part.
// With a leading 0x28 0xB5 0x2F 0xFD (the zstd magic) the whole input goes through the stream decoder.
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
  rtr::ObjOptions opt;
  opt.warn = [](const std::string&) {};
  opt.threads = 1;
  std::string lastMtl;  // an error in the MTL part names the MTL
  try {
    auto src = rtr::memorySource(obj, "fuzz.obj", zstd);
    auto readMtl = [&](const std::string& name) {
      lastMtl = name;
      return mtl;
    };
    rtr::fuzz::checkScene(rtr::parseObj(*src, "fuzz.obj", readMtl, opt));
  } catch (const rtr::Error& e) {
    if (lastMtl.empty() || !std::strstr(e.what(), lastMtl.c_str())) rtr::fuzz::requireNamesFile(e, "fuzz.obj");
  }
  return 0;
}
