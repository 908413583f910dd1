// Fuzzes the texture cache's entries (scene/texture_cache.hpp): the input is an entry file, read through
// TextureCache::find as a four-channel texture would be. find never throws: an entry it refuses is removed
// and reported as a miss; one it takes has the texture's channels and a chain whose every piece unpacks to
// its size, or a refusal naming the file (the fuzz build does not enforce the entry's checksum).
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "check.hpp"
#include "scene/baked_texels.hpp"
#include "scene/texture_cache.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rtr;
  static const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("rtr-fuzz-texture-cache-" + std::to_string(::getpid()));
  static TextureCache cache(dir, uint64_t(1) << 30);
  // The key the seeds were written with (tests/fuzz/corpus/fuzz_texture_cache).
  static const TextureCacheKey key{1, 2, "fuzz"};
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / key.fileName();
  std::ofstream(file, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
  const Texture texture{"fuzz.png", true, 4};
  const std::shared_ptr<const BakedTexels> chain = cache.find(key, texture);
  if (!chain) {
    fuzz::require(!std::filesystem::exists(file), "a refused entry was kept");
    return 0;
  }
  fuzz::require(bakedChannels(chain->format) == 4 && !bakedBlocks(chain->format), "the entry's texel format");
  std::vector<uint8_t> texels(chain->bytes());
  try {
    for (size_t k = 0; k < chain->pieces.size(); ++k) unpackBakedPiece(*chain, k, texels.data());
  } catch (const Error& e) { fuzz::requireNamesFile(e, file.c_str()); }
  return 0;
}
