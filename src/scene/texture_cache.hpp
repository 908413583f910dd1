#pragma once
// Decoded, mipped textures of files opened directly (OBJ, glTF), kept in the user's cache folder so that
// the next open of the same model neither decodes nor filters them (docs/startup.md, "The texture cache").
// An entry is one texture's whole chain in the encoding of .rtrscene's TEXS chunk (scene/baked_texels.hpp:
// lossless, zstd pieces), behind a header that names what made it and a checksum over the rest.
//
// Keyed by content: the encoded image's bytes (checksum64 and length), the texels its slot decodes to
// (channels, the channel picked, sRGB) and the caller's `variant`, which names everything else that makes
// the chain (the mip filter and its version; for GPU chains the device and driver that ran it). The same
// key always gives the same texels: a cached open draws exactly what an uncached one draws.
//
// Several processes may share the folder: entries are written to a temporary and renamed (core/atomic_file),
// a damaged or short entry is ignored (one note), removed and written again, and the folder is kept under a
// size bound by removing the entries used least recently (an entry's modification time is its last use).
// No GPU here.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "scene/baked_texels.hpp"
#include "scene/scene.hpp"

namespace rtr {

constexpr uint64_t kTextureCacheDefaultMiB = 2048;

struct TextureCacheKey {
  uint64_t content = 0, contentBytes = 0;  // checksum64 of the encoded image, its length
  std::string params;                      // the decoded texels' form and the caller's variant
  std::string fileName() const;            // the entry's file name in the folder
};

struct TextureCacheCounts {
  std::atomic<uint32_t> hits{0}, misses{0}, stored{0}, damaged{0}, evicted{0};
  std::atomic<uint32_t> hashed{0};      // keys made by reading and hashing the image's bytes
  std::atomic<uint32_t> remembered{0};  // keys of files unchanged since an earlier open: neither read nor hashed
};

class TextureCache {
 public:
  // `dir`: the folder (created when the first entry is stored); entries are kept under `maxBytes` in all.
  TextureCache(std::filesystem::path dir, uint64_t maxBytes);
  // The cache the environment asks for: RTR_TEXTURE_CACHE=DIR|off (default: "textures" in core/user_cache's
  // folder), RTR_TEXTURE_CACHE_MB=N (default kTextureCacheDefaultMiB). Null when off or no folder is known.
  // A bad RTR_TEXTURE_CACHE_MB throws UsageError.
  static std::unique_ptr<TextureCache> fromEnvironment();

  const std::filesystem::path& dir() const { return dir_; }
  uint64_t maxBytes() const { return maxBytes_; }

  // The key of texture `t` of `scene` (its file, or its bytes held in memory), for chains made as `variant`
  // says. False when the image cannot be read (the decoder then says why). A file's content checksum is
  // remembered in the folder (a small *.rtrkey record) under its path, size, modification time and inode,
  // so that the next open of an unchanged file neither reads nor hashes it; a file modified in the last two
  // seconds is hashed every time. Thread-safe.
  bool key(const Scene& scene, const Texture& t, const std::string& variant, TextureCacheKey& out);

  // The entry's chain (lossless, the channels of `t`'s slot), its use recorded; null when there is none or
  // it is damaged (then removed, one note on stderr). Counts a hit or a miss. Thread-safe.
  std::shared_ptr<const BakedTexels> find(const TextureCacheKey& key, const Texture& t);
  // Writes `chain` as the entry for `key` (atomically; a failure is a note: the cache only saves time).
  // An entry larger than the bound is not kept. Thread-safe; trim() afterwards.
  void store(const TextureCacheKey& key, std::shared_ptr<const BakedTexels> chain);
  // Removes the least recently used entries until the folder holds at most maxBytes().
  void trim();

  const TextureCacheCounts& counts() const { return counts_; }

 private:
  bool fileKey(const std::filesystem::path& file, TextureCacheKey& out);
  std::filesystem::path dir_;
  uint64_t maxBytes_;
  TextureCacheCounts counts_;
};

}  // namespace rtr
