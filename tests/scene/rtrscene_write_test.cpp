// The .rtrscene written while it is made (writeRtrScene: windows summed on all cores, written by a thread
// of their own, chunk sizes patched into pieces held back) is byte for byte the in-memory encoding, at any
// thread count and window size; a streaming ByteWriter gives the bytes and the piece checksum of one in
// memory for any sequence of writes, holes and patches; a write error names the file; written beside the
// clusters' build (rtr-bake), it is the file written after them.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <random>
#include <thread>

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

// rtr-bake writes the file beside the clusters' build: the writer takes each mesh's indices as the build
// makes them final (ClusterProgress) and gives the bytes of a file written after it. The writer is let run
// until it waits for the first indices (or ends: a writer that does not wait writes the indices unclustered).
TEST(RtrSceneWrite, WrittenBesideTheClustersIsTheFileWrittenAfterThem) {
  for (unsigned threads : {1u, 3u}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    Scene s = everything();
    for (Mesh& m : s.meshes) m.clusters.clear(), m.lod = {};
    s.meshes[4].clusters.push_back(Cluster{});  // built already: not waited for
    Scene after = s;
    buildMissingClusters(after, threads);
    after.meshes[2].lod = buildClusterLod(after.meshes[2]);
    const std::string expected = encodeRtrScene(after);
    TempDir tmp;
    const auto out = tmp.dir / "beside.rtrscene";
    AtomicFile f(out);
    ClusterProgress built(s);
    std::mutex m;
    std::condition_variable cv;
    bool waiting = false, ended = false;
    std::vector<std::pair<size_t, size_t>> gates;
    std::thread writer([&] {
      writeRtrScene(s, f, threads, kMiB, [&](size_t mesh, size_t triangles) {
        {
          std::lock_guard lock(m);
          waiting = true;
          gates.push_back({mesh, triangles});
        }
        cv.notify_all();
        built.wait(mesh, triangles);
      });
      std::lock_guard lock(m);
      ended = true;
      cv.notify_all();
    });
    {
      std::unique_lock lock(m);
      cv.wait(lock, [&] { return waiting || ended; });
    }
    buildMissingClusters(s, threads, &built);
    s.meshes[2].lod = buildClusterLod(s.meshes[2]);
    built.finish();
    writer.join();
    f.commit();
    EXPECT_TRUE(fileBytes(out) == expected);
    // The big mesh (180 000 triangles) in three blocks, then its clusters; the chunks last.
    const std::vector<std::pair<size_t, size_t>> big = {{1, 65536}, {1, 131072}, {1, 180000}, {1, 180000}};
    EXPECT_TRUE(std::search(gates.begin(), gates.end(), big.begin(), big.end()) != gates.end());
    ASSERT_FALSE(gates.empty());
    EXPECT_EQ(gates.back(), std::make_pair(s.meshes.size(), size_t(0)));
  }
}

// Pieces end in any order; a mesh's triangles are final up to the first piece not yet done, and the one
// call that completes it is told so (it sets the clusters; meshDone then lets the last indices go).
TEST(RtrSceneWrite, ClusterProgressFollowsThePiecesInOrder) {
  Scene s;
  s.meshes = {grid(4, 0.0f), grid(2, 5.0f), Mesh{}};
  s.meshes[1].clusters.push_back(Cluster{});
  ClusterProgress p(s);
  EXPECT_EQ(p.finalTriangles(0), 0u);
  EXPECT_EQ(p.finalTriangles(1), 8u);  // has clusters: final
  EXPECT_EQ(p.finalTriangles(2), 0u);
  p.wait(1, 8);
  p.wait(2, 0);
  EXPECT_FALSE(p.pieceDone(0, 2, 3, 32));
  EXPECT_EQ(p.finalTriangles(0), 0u);
  EXPECT_FALSE(p.pieceDone(0, 0, 3, 10));
  EXPECT_EQ(p.finalTriangles(0), 10u);
  p.wait(0, 10);
  EXPECT_TRUE(p.pieceDone(0, 1, 3, 20));
  EXPECT_EQ(p.finalTriangles(0), 32u);
  std::atomic<bool> through{false};
  std::thread last([&] { p.wait(0, 32), through = true; });  // waits for meshDone: the clusters
  p.meshDone(0);
  last.join();
  EXPECT_TRUE(through);
  std::thread chunks([&] { p.wait(3, 0); });  // the chunks: after finish()
  p.finish();
  chunks.join();
}

// A mesh of fewer than 3 indices has no piece: it is complete once the build has run (no writer waits on).
TEST(RtrSceneWrite, AMeshWithoutATriangleIsDoneWhenTheBuildIs) {
  Scene s;
  s.meshes = {grid(2, 0.0f), grid(2, 5.0f)};
  s.meshes[0].indices = std::vector<uint32_t>{0, 1};
  ClusterProgress p(s);
  buildMissingClusters(s, 2, &p);
  p.wait(0, 0);
  p.wait(1, 8);
  EXPECT_TRUE(s.meshes[0].clusters.empty());
  EXPECT_FALSE(s.meshes[1].clusters.empty());
}

// A build that fails lets a waiting writer go with an error (rtr-bake then reports the build's error).
TEST(RtrSceneWrite, AFailedClusterBuildStopsTheWriter) {
  Scene s;
  s.meshes = {grid(4, 0.0f)};
  s.meshes[0].indices.writable()[7] = 1000;  // out of range
  ClusterProgress p(s);
  std::string waited;
  std::thread writer([&] {
    try {
      p.wait(0, 32);
    } catch (const Error& e) { waited = e.what(); }
  });
  EXPECT_THROW(buildMissingClusters(s, 2, &p), Error);
  writer.join();
  EXPECT_THAT(waited, HasSubstr("clusters were not built"));
}
