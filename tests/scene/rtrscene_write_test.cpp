// The .rtrscene written while it is made (writeRtrScene: windows summed on all cores, written by a thread
// of their own, chunk sizes patched into pieces held back) is byte for byte the in-memory encoding, at any
// thread count and window size; a streaming ByteWriter gives the bytes and the piece checksum of one in
// memory for any sequence of writes, holes and patches; a write error names the file.
#include <fcntl.h>
#include <unistd.h>

#include <cmath>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "scene/baked_texels.hpp"
#include "scene/binio.hpp"
#include "scene/cluster_lod.hpp"
#include "scene/clusters.hpp"
#include "scene/rtrscene.hpp"

using namespace rtr;
using ::testing::HasSubstr;

namespace {

constexpr size_t kMiB = size_t(1) << 20;

std::string fileBytes(const std::filesystem::path& p) {
  const std::vector<uint8_t> b = readFileBytes(p);
  return {b.begin(), b.end()};
}

struct TempDir {
  std::filesystem::path dir;
  TempDir() {
    std::string t = (std::filesystem::temp_directory_path() / "rtr-write-XXXXXX").string();
    dir = ::mkdtemp(t.data());
  }
  ~TempDir() { std::filesystem::remove_all(dir); }
};

Mesh grid(uint32_t n, float x0) {
  Mesh m;
  m.name = "grid" + std::to_string(n);
  for (uint32_t y = 0; y <= n; ++y)
    for (uint32_t x = 0; x <= n; ++x) {
      const float fx = float(x) / float(n), fy = float(y) / float(n);
      m.positions.push_back({x0 + fx * 4.0f, 0.3f * std::sin(fx * 17.0f) * std::cos(fy * 11.0f), fy * 4.0f});
      m.normals.push_back(glm::normalize(glm::vec3(fx, 1.0f, fy)));
      m.texcoords.push_back({fx, fy});
    }
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      const uint32_t a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
      m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
    }
  for (const glm::vec3& p : m.positions) m.bounds.extend(p);
  return m;
}

// Every part of the format, several MiB of it: a big mesh (32-bit indices), small ones (16-bit), clusters,
// a hierarchy (CLOD) and a noisy baked texture (TEXS, stored as it is: its chunk spans several windows).
Scene everything() {
  Scene s;
  Texture t{"t.png", true, 4};
  BakedTexels layout;
  layout.width = layout.height = 700;
  std::vector<uint8_t> chain(layout.bytes());
  std::mt19937 rng(3);
  for (uint8_t& b : chain) b = uint8_t(rng());
  t.baked = packBakedTexels(BakedFormat::Rgba8, 700, 700, chain);
  s.textures = {t};
  s.materials.resize(2);
  s.materials[1].textures[0] = 0;
  s.meshes = {grid(20, 0.0f), grid(300, 5.0f), grid(60, -5.0f), Mesh{}, grid(7, 10.0f)};
  s.meshes[1].material = 1;
  s.meshes[3].name = "empty";
  s.lights.push_back(Light{});
  s.defaultView = CameraPose{};
  buildMissingClusters(s);
  s.meshes[2].lod = buildClusterLod(s.meshes[2]);
  return s;
}

TEST(RtrSceneWrite, StreamedBytesAreTheEncodedBytesAtAnyThreadCountAndWindow) {
  const Scene s = everything();
  const std::string expected = encodeRtrScene(s);
  ASSERT_GT(expected.size(), 5 * kMiB);
  ASSERT_NE(expected.find("TEXS"), std::string::npos);
  ASSERT_NE(expected.find("CLOD"), std::string::npos);
  TempDir tmp;
  for (unsigned threads : {1u, 2u, 5u})
    for (size_t window : {kMiB, 3 * kMiB, 64 * kMiB}) {
      SCOPED_TRACE("threads " + std::to_string(threads) + ", window " + std::to_string(window));
      const auto out = tmp.dir / ("t" + std::to_string(threads) + "-" + std::to_string(window) + ".rtrscene");
      AtomicFile f(out);
      EXPECT_EQ(writeRtrScene(s, f, threads, window), expected.size());
      f.commit();
      const std::string got = fileBytes(out);
      ASSERT_EQ(got.size(), expected.size());
      EXPECT_TRUE(got == expected);
    }
  // And the file loads (checksum, chunks and all).
  EXPECT_EQ(loadRtrScene(tmp.dir / "t2-1048576.rtrscene").meshes[2].lod.clusters.size(), s.meshes[2].lod.clusters.size());
}

// Random writes of every kind against the same writes in memory.
TEST(RtrSceneWrite, StreamingWriterMatchesMemoryForAnyWrites) {
  TempDir tmp;
  std::vector<char> data(8 * kMiB);  // more than the largest copy (2 windows of 3 MiB)
  std::mt19937 fill(9);
  for (char& c : data) c = char(fill());
  for (uint32_t seed = 1; seed <= 6; ++seed) {
    std::mt19937 rng(seed);
    const size_t sumFrom = seed % 2 ? 80 : 0, window = (1 + seed % 3) * kMiB;
    const unsigned threads = 1 + seed % 3;
    SCOPED_TRACE("seed " + std::to_string(seed));
    const auto path = tmp.dir / ("w" + std::to_string(seed));
    AtomicFile f(path);
    ByteWriter mem, stream(f.fd(), path.string(), sumFrom, threads, window);
    mem.zeros(sumFrom);
    stream.zeros(sumFrom);
    std::vector<std::pair<size_t, size_t>> holes;  // where, how long
    for (int op = 0; op < 40; ++op) {
      const int kind = int(rng() % 6);
      if (kind == 0) {  // a large copy, up to two windows
        const size_t n = rng() % (2 * window), at = rng() % (data.size() - n);
        mem.bytes(data.data() + at, n);
        stream.bytes(data.data() + at, n);
      } else if (kind == 1) {
        const size_t n = rng() % 5000;
        mem.zeros(n);
        stream.zeros(n);
      } else if (kind == 2) {  // a hole, often across a piece's end
        const size_t n = 1 + rng() % 16;
        const size_t to = kMiB - (stream.size() - sumFrom) % kMiB;
        if (rng() % 2 && to < 64 * kMiB) {
          mem.zeros(to > 4 ? to - 4 : 0);
          stream.zeros(to > 4 ? to - 4 : 0);
        }
        const size_t at = mem.hole(n);
        EXPECT_EQ(stream.hole(n), at);
        holes.push_back({at, n});
      } else if (kind == 3 && !holes.empty()) {  // a hole filled, written long ago or just now
        const size_t k = rng() % holes.size();
        std::vector<char> v(holes[k].second);
        for (char& c : v) c = char(rng());
        mem.patch(holes[k].first, v.data(), v.size());
        stream.patch(holes[k].first, v.data(), v.size());
      } else {
        const uint32_t v = rng();
        mem.u32(v);
        stream.u32(v);
        mem.pad(16);
        stream.pad(16);
      }
    }
    EXPECT_EQ(stream.size(), mem.size());
    EXPECT_EQ(stream.finishPayload(sumFrom, threads), mem.finishPayload(sumFrom));
    if (sumFrom) {  // before the payload: patched after the end, as the header is
      mem.patch(8, "header", 6);
      stream.patch(8, "header", 6);
    }
    f.commit();
    EXPECT_TRUE(fileBytes(path) == mem.data());
  }
}

TEST(RtrSceneWrite, WriteErrorNamesTheFile) {
  const int fd = ::open("/dev/full", O_WRONLY | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  try {
    ByteWriter w(fd, "out/x.rtrscene", 80, 2, kMiB);
    std::vector<char> big(5 * kMiB, 'a');
    w.bytes(big.data(), big.size());
    w.finishPayload(80, 2);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("out/x.rtrscene"));
    EXPECT_THAT(e.what(), HasSubstr("cannot write"));
  }
  ::close(fd);
}

}  // namespace
