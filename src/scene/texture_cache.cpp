#include "scene/texture_cache.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <ctime>
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
// A file's content key remembered under its path, size, modification time and inode: RTRKEY1\0, checksum64
// of the rest, then the file's identity (that string), its content checksum64 and length.
constexpr char kKeyMagic[8] = {'R', 'T', 'R', 'K', 'E', 'Y', '1', '\0'};
constexpr char kKeyExtension[] = ".rtrkey";
// A file modified less than this long ago is hashed every time: a later write within the file system's time
// granularity could keep its size and modification time.
constexpr int64_t kSettledNs = 2'000'000'000;
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

bool TextureCache::key(const Scene& scene, const Texture& t, const std::string& variant, TextureCacheKey& out) {
  if (t.bytes) {
    out.content = checksum64(*t.bytes);
    out.contentBytes = t.bytes->size();
    ++counts_.hashed;
  } else if (!fileKey(t.path.is_absolute() ? t.path : scene.baseDir / t.path, out)) {
    return false;
  }
  out.params = std::string(kDecoder) + "; channels " + std::to_string(decodeChannels(t)) + "; pick " +
               std::to_string(decodeChannels(t) == 1 ? t.sourceChannel : 0) + "; srgb " + std::to_string(decodeSrgb(t)) + "; " +
               variant;
  return true;
}

// The content key of an image file: remembered from an earlier open while the file's path, size,
// modification time and inode are unchanged (no read, no hash), else read and hashed (and remembered once
// the file has not changed for kSettledNs).
bool TextureCache::fileKey(const fs::path& file, TextureCacheKey& out) {
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) return false;
  std::error_code ec;
  std::string id = fs::absolute(file, ec).string();
  for (const int64_t v :
       {int64_t(st.st_size), int64_t(st.st_mtim.tv_sec), int64_t(st.st_mtim.tv_nsec), int64_t(st.st_ino), int64_t(st.st_dev)})
    id += '\0' + std::to_string(v);
  const fs::path alias = dir_ / (hex(checksumOf(id)) + kKeyExtension);
  const size_t body = id.size() + 16;
  try {
    const std::vector<uint8_t> a = readFileBytes(alias);
    uint64_t sum = 0;
    if (a.size() == 16 + body && std::memcmp(a.data(), kKeyMagic, 8) == 0 &&
        (std::memcpy(&sum, a.data() + 8, 8), sum == checksum64(std::span(a).subspan(16))) &&
        std::memcmp(a.data() + 16, id.data(), id.size()) == 0) {
      std::memcpy(&out.content, a.data() + 16 + id.size(), 8);
      std::memcpy(&out.contentBytes, a.data() + 24 + id.size(), 8);
      if (out.contentBytes == uint64_t(st.st_size)) {
        ++counts_.remembered;
        return true;
      }
    }
  } catch (const Error&) {}  // none yet (or unreadable): hashed below
  std::vector<uint8_t> bytes;
  try {
    bytes = readFileBytes(file);
  } catch (const Error&) { return false; }
  out.content = checksum64(bytes);
  out.contentBytes = bytes.size();
  ++counts_.hashed;
  timespec now{};
  ::clock_gettime(CLOCK_REALTIME, &now);
  if ((int64_t(now.tv_sec) - st.st_mtim.tv_sec) * 1'000'000'000 + (now.tv_nsec - st.st_mtim.tv_nsec) < kSettledNs ||
      bytes.size() != uint64_t(st.st_size))
    return true;
  std::string a(16, '\0');
  std::memcpy(a.data(), kKeyMagic, 8);
  a += id;
  a.append(reinterpret_cast<const char*>(&out.content), 8).append(reinterpret_cast<const char*>(&out.contentBytes), 8);
  const uint64_t sum = checksum64({reinterpret_cast<const uint8_t*>(a.data()) + 16, body});
  std::memcpy(a.data() + 8, &sum, 8);
  try {
    fs::create_directories(dir_);
    writeFileAtomic(alias, a);
  } catch (const std::exception& e) { note(alias.string() + ": not written: " + e.what()); }
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
    // Mapped, not read: the chain's pieces are unpacked from the page cache straight into staging memory.
    // Safe beside other processes: entries are replaced by a rename, never rewritten in place.
    const auto mapped = std::make_shared<const MappedFile>(file, "texture cache entry");
    const std::span<const uint8_t> bytes = mapped->bytes();
    ByteReader r(bytes, file.string());
    char magic[8];
    r.raw(magic, 8, "the entry's header");
    if (std::memcmp(magic, kMagic, 8) != 0) r.failAt(0, "not a texture cache entry");
    if (r.u32("the entry's header") != kVersion) r.failAt(8, "another version");
    const uint32_t paramsBytes = r.u32("the entry's header");
    const uint64_t content = r.pod<uint64_t>("the entry's header"), contentBytes = r.pod<uint64_t>("the entry's header");
    const uint64_t size = r.pod<uint64_t>("the entry's header"), sum = r.pod<uint64_t>("the entry's header");
    if (size != bytes.size() - kHeader) r.failAt(32, "truncated or padded");
#ifndef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION  // the fuzzer reaches the parser behind it
    if (checksum64(bytes.subspan(kHeader)) != sum) r.failAt(40, "checksum mismatch");
#else
    (void)sum;
#endif
    if (content != key.content || contentBytes != key.contentBytes || r.view(paramsBytes, "the entry's key") != key.params)
      r.failAt(16, "made for another image");  // a file-name clash: it is replaced by this image's entry
    r.align(16, "the entry's key");
    Scene one = oneTexture(uint32_t(decodeChannels(t)));
    readTexs(r, bytes.size(), bytes, one, mapped, file.string());
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
    if (p.extension() != kExtension && p.extension() != kKeyExtension) continue;
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
