#include "scene/texture_cache.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/user_cache.hpp"
#include "scene/binio.hpp"
#include "scene/rtrscene_texs.hpp"
#include "scene/textures.hpp"

namespace rtr {
namespace {

namespace fs = std::filesystem;

constexpr char kMagic[8] = {'R', 'T', 'R', 'T', 'E', 'X', 'C', '1'};
constexpr uint32_t kVersion = 1;
constexpr size_t kHeader = 48;  // magic, version, params length, content, content bytes, body bytes, checksum
constexpr char kExtension[] = ".rtrtex";
// Bumped when the decoders' texels for the same bytes change (the image library, the channel pick).
constexpr char kDecoder[] = "decode 1";

void note(const std::string& s) { std::fprintf(stderr, "note: texture cache: %s\n", s.c_str()); }

std::string hex(uint64_t v) {
  char b[17];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
  return b;
}

uint64_t checksumOf(const std::string& s) { return checksum64({reinterpret_cast<const uint8_t*>(s.data()), s.size()}); }

// A one-texture scene whose TEXS body is an entry's: the texture's slot decodes to `channels`.
Scene oneTexture(uint32_t channels, std::shared_ptr<const BakedTexels> chain = nullptr) {
  Scene s;
  Texture t;
  t.channels = uint8_t(channels);
  t.baked = std::move(chain);
  s.textures.push_back(std::move(t));
  return s;
}

}  // namespace

std::string TextureCacheKey::fileName() const {
  return hex(content) + "-" + hex(contentBytes) + "-" + hex(checksumOf(params)) + kExtension;
}

TextureCache::TextureCache(std::filesystem::path dir, uint64_t maxBytes) : dir_(std::move(dir)), maxBytes_(maxBytes) {}

std::unique_ptr<TextureCache> TextureCache::fromEnvironment() {
  uint64_t mib = kTextureCacheDefaultMiB;
  if (const char* m = std::getenv("RTR_TEXTURE_CACHE_MB"); m && *m) {
    char* end = nullptr;
    const unsigned long long v = std::strtoull(m, &end, 10);
    if (*end != '\0' || *m == '-' || v < 1 || v > (uint64_t(1) << 30))
      throw UsageError(std::string("RTR_TEXTURE_CACHE_MB=") + m + ": not a size in MiB (1 to 2^30)");
    mib = v;
  }
  fs::path dir;
  if (const char* c = std::getenv("RTR_TEXTURE_CACHE"); c && *c) {
    if (std::string_view(c) == "off") return nullptr;
    dir = c;
  } else if (const fs::path base = userCacheDir(); !base.empty()) {
    dir = base / "textures";
  }
  if (dir.empty()) return nullptr;
  return std::make_unique<TextureCache>(dir, mib << 20);
}

bool TextureCache::key(const Scene& scene, const Texture& t, const std::string& variant, TextureCacheKey& out) const {
  std::vector<uint8_t> file;
  std::span<const uint8_t> bytes;
  if (t.bytes) {
    bytes = *t.bytes;
  } else {
    try {
      file = readFileBytes(t.path.is_absolute() ? t.path : scene.baseDir / t.path);
    } catch (const Error&) { return false; }
    bytes = file;
  }
  out.content = checksum64(bytes);
  out.contentBytes = bytes.size();
  out.params = std::string(kDecoder) + "; channels " + std::to_string(decodeChannels(t)) + "; pick " +
               std::to_string(decodeChannels(t) == 1 ? t.sourceChannel : 0) + "; srgb " + std::to_string(decodeSrgb(t)) + "; " +
               variant;
  return true;
}

std::shared_ptr<const BakedTexels> TextureCache::find(const TextureCacheKey& key, const Texture& t) {
  const fs::path file = dir_ / key.fileName();
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    ++counts_.misses;
    return nullptr;
  }
  try {
    auto bytes = std::make_shared<std::vector<uint8_t>>(readFileBytes(file));
    ByteReader r(*bytes, file.string());
    char magic[8];
    r.raw(magic, 8, "the entry's header");
    if (std::memcmp(magic, kMagic, 8) != 0) r.failAt(0, "not a texture cache entry");
    if (r.u32("the entry's header") != kVersion) r.failAt(8, "another version");
    const uint32_t paramsBytes = r.u32("the entry's header");
    const uint64_t content = r.pod<uint64_t>("the entry's header"), contentBytes = r.pod<uint64_t>("the entry's header");
    const uint64_t size = r.pod<uint64_t>("the entry's header"), sum = r.pod<uint64_t>("the entry's header");
    if (size != bytes->size() - kHeader) r.failAt(32, "truncated or padded");
#ifndef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION  // the fuzzer reaches the parser behind it
    if (checksum64(std::span<const uint8_t>(*bytes).subspan(kHeader)) != sum) r.failAt(40, "checksum mismatch");
#else
    (void)sum;
#endif
    if (content != key.content || contentBytes != key.contentBytes || r.view(paramsBytes, "the entry's key") != key.params)
      r.failAt(16, "made for another image");  // a file-name clash: it is replaced by this image's entry
    r.align(16, "the entry's key");
    Scene one = oneTexture(uint32_t(decodeChannels(t)));
    readTexs(r, bytes->size(), *bytes, one, bytes, file.string());
    std::shared_ptr<const BakedTexels> chain = one.textures[0].baked;
    if (bakedBlocks(chain->format)) r.failAt(kHeader, "block-compressed texels");
    fs::last_write_time(file, fs::file_time_type::clock::now(), ec);  // its last use, for the size bound
    ++counts_.hits;
    return chain;
  } catch (const std::exception& e) {
    note(std::string(e.what()) + "; ignored and written again");
    ++counts_.damaged;
    ++counts_.misses;
    fs::remove(file, ec);
    return nullptr;
  }
}

void TextureCache::store(const TextureCacheKey& key, std::shared_ptr<const BakedTexels> chain) {
  const fs::path file = dir_ / key.fileName();
  try {
    ByteWriter body;
    body.bytes(key.params.data(), key.params.size());
    body.pad(16);  // the entry's header is 48 bytes: the TEXS body starts 16-aligned
    const uint32_t channels = bakedChannels(chain->format);
    writeTexs(body, oneTexture(channels, std::move(chain)));
    if (kHeader + body.size() > maxBytes_) return;
    ByteWriter w;
    w.bytes(kMagic, 8);
    w.u32(kVersion);
    w.u32(uint32_t(key.params.size()));
    w.pod(key.content);
    w.pod(key.contentBytes);
    w.pod(uint64_t(body.size()));
    w.pod(checksum64({reinterpret_cast<const uint8_t*>(body.data().data()), body.size()}));
    w.bytes(body.data().data(), body.size());
    fs::create_directories(dir_);
    writeFileAtomic(file, w.data());
    ++counts_.stored;
  } catch (const std::exception& e) { note(file.string() + ": not written: " + e.what()); }
}

void TextureCache::trim() {
  struct Entry {
    fs::path path;
    uint64_t bytes;
    fs::file_time_type used;
  };
  std::vector<Entry> entries;
  uint64_t total = 0;
  std::error_code ec;
  for (fs::directory_iterator it(dir_, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::path& p = it->path();
    const std::string name = p.filename().string();
    if (const size_t tmp = name.find(".rtrtmp-"); name.starts_with(".") && tmp != std::string::npos) {
      removeStaleTemporaries(dir_ / name.substr(1, tmp - 1));  // what a killed writer left
      continue;
    }
    if (p.extension() != kExtension) continue;
    std::error_code e1, e2;
    const uint64_t bytes = it->file_size(e1);
    const fs::file_time_type used = it->last_write_time(e2);
    if (e1 || e2) continue;  // removed by another process meanwhile
    entries.push_back({p, bytes, used});
    total += bytes;
  }
  if (total <= maxBytes_) return;
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.used < b.used; });
  for (const Entry& e : entries) {
    if (total <= maxBytes_) break;
    if (fs::remove(e.path, ec)) ++counts_.evicted;
    total -= e.bytes;
  }
}

}  // namespace rtr
