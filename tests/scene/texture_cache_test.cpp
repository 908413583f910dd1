// The texture cache's folder (scene/texture_cache.hpp): entries found again with the same texels, keys that
// follow the image and its slot, damaged entries ignored and written again, the size bound removing the
// least recently used, and two processes writing one entry at once.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include <gtest/gtest.h>

#include "scene/baked_texels.hpp"
#include "scene/texture_cache.hpp"
#include "test_paths.hpp"

namespace rtr {
namespace {

namespace fs = std::filesystem;

class TextureCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() /
          ("rtr-texcache-" + std::to_string(::getpid()) + "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir;
};

// A w x h RGBA chain of noise (zstd cannot shrink it: an entry's size is known), packed.
std::shared_ptr<const BakedTexels> noiseChain(uint32_t seed, uint32_t w = 64, uint32_t h = 64) {
  BakedTexels layout;
  layout.width = w;
  layout.height = h;
  std::vector<uint8_t> bytes(layout.bytes());
  std::mt19937 rng(seed);
  for (uint8_t& b : bytes) b = uint8_t(rng());
  return packBakedTexels(BakedFormat::Rgba8, w, h, std::move(bytes), 1);
}

std::vector<uint8_t> unpacked(const BakedTexels& t) {
  std::vector<uint8_t> out(t.bytes());
  for (size_t k = 0; k < t.pieces.size(); ++k) unpackBakedPiece(t, k, out.data());
  return out;
}

TextureCacheKey keyOf(uint64_t n) { return {n, 1000 + n, "test variant"}; }
Texture rgba() { return Texture{"x.png", true, 4}; }

TEST_F(TextureCacheTest, AStoredChainIsFoundWithTheSameTexels) {
  TextureCache cache(dir, uint64_t(1) << 30);
  const auto chain = noiseChain(1);
  EXPECT_EQ(cache.find(keyOf(1), rgba()), nullptr);  // nothing yet (and no folder)
  cache.store(keyOf(1), chain);
  const auto got = cache.find(keyOf(1), rgba());
  ASSERT_NE(got, nullptr);
  EXPECT_EQ(got->width, 64u);
  EXPECT_EQ(got->format, BakedFormat::Rgba8);
  EXPECT_EQ(unpacked(*got), unpacked(*chain));
  TextureCacheKey other = keyOf(1);
  other.params += " 2";  // another slot or variant: another entry
  EXPECT_EQ(cache.find(other, rgba()), nullptr);
  EXPECT_EQ(cache.counts().hits, 1u);
  EXPECT_EQ(cache.counts().misses, 2u);
  EXPECT_EQ(cache.counts().stored, 1u);
}

// The fuzz target's seed, written byte by byte from the layout docs/startup.md gives (a 4x4 RGBA chain of
// 96 bytes stored as they are, key {1, 2, "fuzz"}), is an entry the cache reads.
TEST_F(TextureCacheTest, AnEntryLaidOutAsDocumentedIsRead) {
  const fs::path seed = test::sourceDir() / "tests/fuzz/corpus/fuzz_texture_cache/rgba-4x4-stored.rtrtex";
  ASSERT_TRUE(fs::exists(seed)) << seed;
  const TextureCacheKey key{1, 2, "fuzz"};
  fs::create_directories(dir);
  fs::copy_file(seed, dir / key.fileName());
  TextureCache cache(dir, uint64_t(1) << 30);
  const auto got = cache.find(key, rgba());
  ASSERT_NE(got, nullptr);
  EXPECT_EQ(got->width, 4u);
  EXPECT_EQ(got->levels(), 3u);
  std::ifstream in(seed, std::ios::binary);
  const std::string bytes(std::istreambuf_iterator<char>(in), {});
  const std::vector<uint8_t> texels(bytes.end() - 96, bytes.end());
  EXPECT_EQ(unpacked(*got), texels);
}

TEST_F(TextureCacheTest, TheKeyFollowsTheImageBytesAndTheSlot) {
  TextureCache cache(dir, uint64_t(1) << 30);
  auto keyName = [&](const Texture& t, const std::string& variant) {
    TextureCacheKey k;
    EXPECT_TRUE(cache.key(Scene{}, t, variant, k));
    return k.fileName();
  };
  Texture a = rgba();
  a.bytes = std::make_shared<const std::vector<uint8_t>>(std::vector<uint8_t>{1, 2, 3, 4});
  Texture b = a;
  b.bytes = std::make_shared<const std::vector<uint8_t>>(std::vector<uint8_t>{1, 2, 3, 5});
  Texture linear = a;
  linear.srgb = false;
  Texture red = a, green = a;
  red.channels = green.channels = 1;
  red.sourceChannel = 1, green.sourceChannel = 2;
  const std::string base = keyName(a, "v");
  EXPECT_EQ(keyName(a, "v"), base);
  for (const std::string& n : {keyName(b, "v"), keyName(linear, "v"), keyName(red, "v"), keyName(a, "w")}) EXPECT_NE(n, base);
  EXPECT_NE(keyName(red, "v"), keyName(green, "v"));
  // A file: its bytes, wherever it is; none: no key.
  fs::create_directories(dir);
  std::ofstream(dir / "t.png", std::ios::binary).write("\x01\x02\x03\x04", 4);
  Texture file = rgba();
  file.path = dir / "t.png";
  EXPECT_EQ(keyName(file, "v"), base);
  file.path = dir / "missing.png";
  TextureCacheKey k;
  EXPECT_FALSE(cache.key(Scene{}, file, "v", k));
}

TEST_F(TextureCacheTest, ADamagedEntryIsIgnoredRemovedAndWrittenAgain) {
  const auto chain = noiseChain(2);
  const std::vector<std::pair<const char*, std::function<void(const fs::path&)>>> damages = {
      {"one byte flipped in the texels",
       [](const fs::path& f) {
         std::fstream s(f, std::ios::in | std::ios::out | std::ios::binary);
         s.seekg(std::streamoff(fs::file_size(f) / 2));
         const char c = char(s.get());
         s.seekp(std::streamoff(fs::file_size(f) / 2));
         s.put(char(c ^ 0x10));
       }},
      {"cut short", [](const fs::path& f) { fs::resize_file(f, fs::file_size(f) - 100); }},
      {"empty", [](const fs::path& f) { fs::resize_file(f, 0); }},
      {"another file's bytes", [](const fs::path& f) { std::ofstream(f, std::ios::binary) << "not a cache entry at all"; }},
  };
  for (const auto& [what, damage] : damages) {
    SCOPED_TRACE(what);
    TextureCache cache(dir, uint64_t(1) << 30);
    cache.store(keyOf(2), chain);
    const fs::path file = dir / keyOf(2).fileName();
    ASSERT_TRUE(fs::exists(file));
    damage(file);
    EXPECT_EQ(cache.find(keyOf(2), rgba()), nullptr);
    EXPECT_EQ(cache.counts().damaged, 1u);
    EXPECT_FALSE(fs::exists(file)) << "a damaged entry is removed";
    cache.store(keyOf(2), chain);  // what a load does after the miss
    const auto again = cache.find(keyOf(2), rgba());
    ASSERT_NE(again, nullptr);
    EXPECT_EQ(unpacked(*again), unpacked(*chain));
  }
}

// A file opened again unchanged is keyed without reading it (its key remembered under its path, size,
// modification time and inode); any of those changed, or a file modified in the last seconds, is read and
// hashed again.
TEST_F(TextureCacheTest, AFileSeenBeforeIsKeyedWithoutReadingIt) {
  TextureCache cache(dir, uint64_t(1) << 30);
  fs::create_directories(dir / "images");
  const fs::path png = dir / "images" / "t.png";
  Texture file = rgba();
  file.path = png;
  const auto write = [&](const std::string& bytes, std::chrono::seconds age) {
    std::ofstream(png, std::ios::binary | std::ios::trunc).write(bytes.data(), std::streamsize(bytes.size()));
    fs::last_write_time(png, fs::file_time_type::clock::now() - age);
  };
  const auto keyName = [&] {
    TextureCacheKey k;
    EXPECT_TRUE(cache.key(Scene{}, file, "v", k));
    return k.fileName();
  };
  Texture inMemory = rgba();
  inMemory.bytes = std::make_shared<const std::vector<uint8_t>>(std::vector<uint8_t>{1, 2, 3, 4});
  write("\x01\x02\x03\x04", std::chrono::hours(1));
  const std::string first = keyName();
  EXPECT_EQ(cache.counts().hashed, 1u);
  EXPECT_EQ(keyName(), first);
  EXPECT_EQ(cache.counts().hashed, 1u) << "an unchanged file was read and hashed again";
  EXPECT_EQ(cache.counts().remembered, 1u);
  {
    TextureCacheKey k;
    cache.key(Scene{}, inMemory, "v", k);
    EXPECT_EQ(k.fileName(), first) << "a remembered key differs from the content's";
    EXPECT_EQ(cache.counts().hashed, 2u);
  }
  write("\x01\x02\x03\x05", std::chrono::minutes(30));  // same size, another time
  EXPECT_NE(keyName(), first);
  EXPECT_EQ(cache.counts().hashed, 3u);
  write("\x01\x02\x03\x04\x05", std::chrono::minutes(30));  // same time, another size
  const std::string longer = keyName();
  EXPECT_EQ(cache.counts().hashed, 4u);
  EXPECT_EQ(keyName(), longer);
  EXPECT_EQ(cache.counts().hashed, 4u);
  write("\x01\x02\x03\x06", std::chrono::seconds(0));  // just written: hashed every time
  const std::string fresh = keyName();
  EXPECT_EQ(keyName(), fresh);
  EXPECT_EQ(cache.counts().hashed, 6u) << "a file written a moment ago was trusted by its time";
  // A damaged record is not believed.
  write("\x01\x02\x03\x07", std::chrono::hours(2));
  const std::string settled = keyName();
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".rtrkey") {
      std::fstream f(e.path(), std::ios::binary | std::ios::in | std::ios::out);
      f.seekp(-9, std::ios::end);  // in the content checksum
      f.put('\x7f');
    }
  EXPECT_EQ(keyName(), settled);
  EXPECT_EQ(cache.counts().hashed, 8u) << "a damaged key record was believed";
}

TEST_F(TextureCacheTest, TheSizeBoundRemovesTheLeastRecentlyUsed) {
  const auto a = noiseChain(3), b = noiseChain(4), c = noiseChain(5);
  uint64_t entry = 0;
  {
    TextureCache probe(dir / "probe", uint64_t(1) << 30);
    probe.store(keyOf(9), a);
    entry = fs::file_size(dir / "probe" / keyOf(9).fileName());
  }
  TextureCache cache(dir / "bounded", entry * 2 + entry / 2);                             // two entries fit, three do not
  const auto later = [] { std::this_thread::sleep_for(std::chrono::milliseconds(30)); };  // file times are coarse
  cache.store(keyOf(3), a);
  later();
  cache.store(keyOf(4), b);
  later();
  ASSERT_NE(cache.find(keyOf(3), rgba()), nullptr);  // a is used again: b is now the least recently used
  later();
  cache.store(keyOf(5), c);
  cache.trim();
  EXPECT_EQ(cache.counts().evicted, 1u);
  EXPECT_TRUE(fs::exists(dir / "bounded" / keyOf(3).fileName()));
  EXPECT_FALSE(fs::exists(dir / "bounded" / keyOf(4).fileName())) << "the least recently used entry stays";
  EXPECT_TRUE(fs::exists(dir / "bounded" / keyOf(5).fileName()));
  // An entry larger than the whole bound is not kept.
  TextureCache tiny(dir / "tiny", entry / 2);
  tiny.store(keyOf(3), a);
  EXPECT_FALSE(fs::exists(dir / "tiny" / keyOf(3).fileName()));
}

TEST_F(TextureCacheTest, TwoProcessesWritingOneEntryAtOnceLeaveAValidEntry) {
  const auto chain = noiseChain(6, 256, 256);  // ~350 KB: a write takes long enough to overlap with reads
  TextureCache reader(dir, uint64_t(1) << 30);
  std::vector<pid_t> writers;
  for (int w = 0; w < 2; ++w) {
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      TextureCache cache(dir, uint64_t(1) << 30);
      for (int i = 0; i < 40; ++i) cache.store(keyOf(6), chain);
      ::_exit(cache.counts().stored == 40 ? 0 : 1);
    }
    writers.push_back(pid);
  }
  // While they write, every read finds the entry whole or not at all.
  std::vector<int> status(writers.size(), -1);
  std::vector<bool> done(writers.size(), false);
  size_t reads = 0;
  while (std::find(done.begin(), done.end(), false) != done.end()) {
    for (size_t k = 0; k < writers.size(); ++k)
      if (!done[k] && ::waitpid(writers[k], &status[k], WNOHANG) == writers[k]) done[k] = true;
    if (const auto got = reader.find(keyOf(6), rgba())) { EXPECT_EQ(unpacked(*got), unpacked(*chain)); }
    ++reads;
  }
  EXPECT_EQ(reader.counts().damaged, 0u) << "a reader saw a partial entry in " << reads << " reads";
  for (int st : status) EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << "a writer failed";
  const auto last = reader.find(keyOf(6), rgba());
  ASSERT_NE(last, nullptr);
  EXPECT_EQ(unpacked(*last), unpacked(*chain));
  size_t files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1u) << "temporaries left behind";
}

}  // namespace
}  // namespace rtr
