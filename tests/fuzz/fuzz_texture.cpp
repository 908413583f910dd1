// Fuzzes texture decoding through the function both renderers use (decodeTextures): the input is the
// file, decoded once as a one-channel texture and once as an sRGB four-channel one. Texels, or a warning
// naming the file (decodeTextures shows a checker for a file it cannot read: the warning is the refusal);
// the texel count matches the size it reports. The warnings go to the check, not to stderr: writing one
// per input halved the executions a second.
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <string>

#include "check.hpp"
#include "scene/textures.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rtr;
  // The decoder reads files: one in-memory file per process, rewritten for each input.
  static const int fd = memfd_create("fuzz-texture", 0);
  static const std::string path = "/proc/self/fd/" + std::to_string(fd);
  fuzz::require(fd >= 0 && ftruncate(fd, 0) == 0 && pwrite(fd, data, size, 0) == ssize_t(size), "memfd write");
  Scene scene;
  scene.textures = {{path, false, 1}, {path, true, 4}};
  const uint32_t which[] = {0, 1};
  try {
    decodeTextures(
        scene, which,
        [&](size_t i, TexelData&& t) {
          fuzz::require(t.channels == uint32_t(decodeChannels(scene.textures[i])), "decoded channel count");
          fuzz::require(t.texels.size() == size_t(t.width) * t.height * t.channels, "texel count differs from the size");
        },
        [&](const std::string& warning) {
          fuzz::require(warning.find(path) != std::string::npos, "the warning does not name the file");
        });
  } catch (const Error& e) { fuzz::requireNamesFile(e, path.c_str()); }
  return 0;
}
