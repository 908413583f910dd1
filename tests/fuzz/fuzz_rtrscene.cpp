// Fuzzes the .rtrscene decoder (the fuzz build skips its checksum, so mutations reach the records).
// A decoded scene must be usable, its baked textures (version 6, TEXS) unpack or fail with an rtr::Error
// naming the file, and re-encoding it must give bytes that decode to the same bytes again.
#include <cstdint>
#include <span>

#include "check.hpp"
#include "scene/baked_texels.hpp"
#include "scene/rtrscene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rtr;
  Scene s;
  try {
    s = decodeRtrScene({data, size}, "fuzz.rtrscene");
  } catch (const Error& e) {
    fuzz::requireNamesFile(e, "fuzz.rtrscene");
    return 0;
  }
  fuzz::checkScene(s);
  for (const Texture& t : s.textures) {
    if (!t.baked) continue;
    std::vector<uint8_t> chain(t.baked->bytes());
    try {
      for (size_t k = 0; k < t.baked->pieces.size(); ++k) unpackBakedPiece(*t.baked, k, chain.data());
    } catch (const Error& e) { fuzz::requireNamesFile(e, "fuzz.rtrscene"); }
  }
  std::string once, twice;
  try {
    once = encodeRtrScene(s);
    twice = encodeRtrScene(decodeRtrScene({reinterpret_cast<const uint8_t*>(once.data()), once.size()}, "again"));
  } catch (const Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    fuzz::require(false, "a decoded scene does not re-encode and decode");
  }
  fuzz::require(once == twice, "encode(decode(encode(scene))) differs from encode(scene)");
  return 0;
}
