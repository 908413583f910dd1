// The .rtrscene decoder on several threads: the scene and any fault it reports are those of one thread;
// the piece checksum (version 4 on) is its definition at any thread count; files of older versions still load.
#include <cmath>
#include <cstring>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "scene/binio.hpp"
#include "scene/clusters.hpp"
#include "scene/rtrscene.hpp"
#include "test_paths.hpp"

using namespace rtr;
using ::testing::HasSubstr;

namespace {

// A height field of n×n quads; `attributes` false leaves out normals and texcoords.
Mesh grid(uint32_t n, float x0, bool attributes) {
  Mesh m;
  m.name = "grid" + std::to_string(n);
  for (uint32_t y = 0; y <= n; ++y)
    for (uint32_t x = 0; x <= n; ++x) {
      const float fx = float(x) / float(n), fy = float(y) / float(n);
      m.positions.push_back({x0 + fx * 4.0f, 0.3f * std::sin(fx * 17.0f) * std::cos(fy * 11.0f), fy * 4.0f});
      if (attributes) m.normals.push_back(glm::vec3(fx, 1.0f, fy));
      if (attributes) m.texcoords.push_back({fx, fy});
    }
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      const uint32_t a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
      m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
    }
  for (const glm::vec3& p : m.positions) m.bounds.extend(p);
  return m;
}

// Several meshes: one big enough that its arrays and clusters are checked in several pieces (32-bit
// indices), small ones with 16-bit indices, one without attributes, one empty; a light and a texture.
Scene severalMeshes() {
  Scene s;
  s.textures.push_back(Texture{"t.png", true, 4});
  s.materials.resize(2);
  s.materials[1].textures[0] = 0;
  s.meshes.push_back(grid(20, 0.0f, true));
  s.meshes.push_back(grid(400, 5.0f, true));  // 160 801 vertices, 960 000 indices, ~2 600 clusters
  s.meshes.push_back(grid(30, -5.0f, false));
  s.meshes.push_back(Mesh{});
  s.meshes.back().name = "empty";
  s.meshes.push_back(grid(7, 10.0f, true));
  s.meshes[1].material = 1;
  s.lights.push_back(Light{});
  buildMissingClusters(s);
  return s;
}

Scene decode(const std::string& bytes, unsigned threads) {
  return decodeRtrScene({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()}, "p.rtrscene", threads);
}

std::string decodeError(const std::string& bytes, unsigned threads) {
  try {
    decode(bytes, threads);
  } catch (const Error& e) { return e.what(); }
  return "(no error)";
}

void expectSameMeshes(const Scene& got, const Scene& want) {
  ASSERT_EQ(got.meshes.size(), want.meshes.size());
  for (size_t i = 0; i < want.meshes.size(); ++i) {
    const Mesh &g = got.meshes[i], &w = want.meshes[i];
    SCOPED_TRACE("mesh " + std::to_string(i));
    EXPECT_EQ(g.name, w.name);
    EXPECT_EQ(g.material, w.material);
    EXPECT_EQ(g.positions, w.positions);
    EXPECT_EQ(g.normals, w.normals);
    EXPECT_EQ(g.texcoords, w.texcoords);
    EXPECT_EQ(g.indices, w.indices);
    ASSERT_EQ(g.clusters.size(), w.clusters.size());
    for (size_t k = 0; k < w.clusters.size(); ++k) {
      const Cluster &a = g.clusters[k], &b = w.clusters[k];
      ASSERT_TRUE(a.firstTriangle == b.firstTriangle && a.triangleCount == b.triangleCount && a.center == b.center &&
                  a.radius == b.radius && a.coneAxis == b.coneAxis && a.coneCutoff == b.coneCutoff)
          << "cluster " << k;
    }
  }
}

void reseal(std::string& b) {
  const uint64_t sum = pieceChecksum64({reinterpret_cast<const uint8_t*>(b.data()) + 80, b.size() - 80});
  std::memcpy(b.data() + 40, &sum, 8);
}

}  // namespace

TEST(RtrSceneParallel, ManyThreadsDecodeWhatOneDoes) {
  const Scene s = severalMeshes();
  const std::string bytes = encodeRtrScene(s);
  ASSERT_GT(bytes.size(), 4u * kChecksumPiece) << "the checksum should run in several pieces";
  const Scene one = decode(bytes, 1);
  expectSameMeshes(one, s);
  for (unsigned threads : {2u, 3u, 8u, 0u}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    const Scene many = decode(bytes, threads);
    expectSameMeshes(many, one);
    EXPECT_EQ(encodeRtrScene(many), bytes);  // everything else (lights, textures, materials, bounds) too
  }
  // The same scene in version 3 (one checksum chain) decodes to the same meshes.
  expectSameMeshes(decode(encodeRtrScene(s, 3), 8), one);
}

// Faults in several pieces: the one at the lowest offset is reported, however many threads ran.
TEST(RtrSceneParallel, TheFirstFaultInTheFileIsReportedAtAnyThreadCount) {
  const Scene s = severalMeshes();
  const std::string good = encodeRtrScene(s);
  // The big mesh's last index (32-bit; 960 000 of them, no padding), just before its cluster header and
  // records, which end where mesh 2 starts: at the size of the file with meshes 0 and 1 only.
  Scene two = s;
  two.meshes.resize(2);
  const size_t clusterSection = 16 + (s.meshes[1].clusters.size() * 40 + 15) / 16 * 16;
  const size_t lastIndexAt = encodeRtrScene(two).size() - clusterSection - 4;
  uint32_t was;
  std::memcpy(&was, good.data() + lastIndexAt, 4);
  ASSERT_EQ(was, s.meshes[1].indices.back());
  std::string b = good;
  const uint32_t bad = 1u << 30;
  std::memcpy(b.data() + lastIndexAt, &bad, 4);
  reseal(b);
  const std::string bigFault = decodeError(b, 1);
  EXPECT_THAT(bigFault, HasSubstr("index 1073741824 out of range (160801 vertices)"));
  // Now also a position of mesh 0, far before it, whose check is among the cheapest pieces and runs last
  // on one thread: that one is reported.
  const glm::vec3 p0 = s.meshes[0].positions[7];
  const size_t posAt = good.find(std::string(reinterpret_cast<const char*>(&p0), 12));
  ASSERT_NE(posAt, std::string::npos);
  const float nan = std::nanf("");
  std::memcpy(b.data() + posAt, &nan, 4);
  reseal(b);
  for (unsigned threads : {1u, 2u, 8u}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    EXPECT_THAT(decodeError(b, threads),
                HasSubstr("p.rtrscene: byte " + std::to_string(posAt) + ": mesh 0: position 7 is not finite"));
  }
}

// A piece of clusters starts from where the record before it says the last one ended: a damaged record
// there must not send the next piece reading past the indices.
TEST(RtrSceneParallel, ADamagedClusterBeforeAPieceIsReportedNotFollowed) {
  const Scene s = severalMeshes();
  ASSERT_GT(s.meshes[1].clusters.size(), 2048u);
  const std::string good = encodeRtrScene(s);
  Scene two = s;
  two.meshes.resize(2);
  const size_t records = encodeRtrScene(two).size() - (s.meshes[1].clusters.size() * 40 + 15) / 16 * 16;
  // Cluster 2047 (the last of the first piece) claims to run to triangle 2^31; cluster 2048 starts there.
  const Cluster& c = s.meshes[1].clusters[2047];
  const uint32_t count = (1u << 31) - c.firstTriangle, first = 1u << 31;
  std::string b = good;
  uint32_t was;
  std::memcpy(&was, b.data() + records + 2047 * 40 + 32, 4);
  ASSERT_EQ(was, c.firstTriangle);
  std::memcpy(b.data() + records + 2047 * 40 + 36, &count, 4);
  std::memcpy(b.data() + records + 2048 * 40 + 32, &first, 4);
  reseal(b);
  for (unsigned threads : {1u, 8u})
    EXPECT_THAT(decodeError(b, threads), HasSubstr("byte " + std::to_string(records + 2047 * 40 + 36) +
                                                   ": mesh 1: cluster 2047: triangle count " + std::to_string(count)));
}

TEST(RtrSceneParallel, PieceChecksumIsItsDefinitionAtAnyThreadCount) {
  std::mt19937 rng(7);
  std::vector<uint8_t> data(9 * kChecksumPiece + 17);
  for (uint8_t& v : data) v = uint8_t(rng());
  for (size_t size : {size_t(0), size_t(5), kChecksumPiece, 4 * kChecksumPiece + 3, data.size()}) {
    const std::span<const uint8_t> d(data.data(), size);
    std::vector<uint64_t> sums;  // the definition: checksum64 of each 1 MiB piece, then of those sums
    for (size_t at = 0; at < size; at += kChecksumPiece)
      sums.push_back(checksum64(d.subspan(at, std::min(kChecksumPiece, size - at))));
    const uint64_t want = checksum64({reinterpret_cast<const uint8_t*>(sums.data()), sums.size() * 8});
    for (unsigned threads : {1u, 3u, 0u})
      EXPECT_EQ(pieceChecksum64(d, threads), want) << size << " bytes, " << threads << " threads";
  }
  // Two pieces swapped: a different sum.
  std::vector<uint8_t> swapped = data;
  std::swap_ranges(swapped.begin(), swapped.begin() + kChecksumPiece, swapped.begin() + kChecksumPiece);
  EXPECT_NE(pieceChecksum64(swapped), pieceChecksum64(data));
}

TEST(RtrSceneParallel, Version4RefusesADamagedPieceAndOlderFilesStillLoad) {
  const std::string good = encodeRtrScene(severalMeshes());
  std::string b = good;
  b[80 + 3 * kChecksumPiece + 11] ^= 4;  // one bit in the fourth piece
  for (unsigned threads : {1u, 8u}) EXPECT_THAT(decodeError(b, threads), HasSubstr("p.rtrscene: byte 40: checksum mismatch"));
  // A file written by a build of version 3 (one checksum chain over the payload) still loads; damaged,
  // it is refused.
  const auto old = readFileBytes(test::sourceDir() / "tests/fuzz/corpus/fuzz_rtrscene/cube_backplane-v3.rtrscene");
  std::string v3(old.begin(), old.end());
  ASSERT_EQ(v3[8], 3);
  EXPECT_EQ(decodeError(v3, 1), "(no error)");
  v3[v3.size() - 20] ^= 1;
  EXPECT_THAT(decodeError(v3, 1), HasSubstr("byte 40: checksum mismatch"));
  std::string v7 = good;
  v7[8] = 7;
  EXPECT_THAT(decodeError(v7, 1), HasSubstr("byte 8: unsupported version 7 (this build reads 6)"));
}

namespace {

// severalMeshes() with a hierarchy on its big mesh (made up, valid as the reader checks it): level 0 its
// ~2 600 clusters, then `above` one-triangle clusters of level 1, so that its records and indices are
// read in several pieces.
Scene withHierarchy(uint32_t above) {
  Scene s = severalMeshes();
  Mesh& m = s.meshes[1];
  m.lod.levels = 2;
  for (const Cluster& c : m.clusters) {
    LodCluster l;
    l.firstTriangle = c.firstTriangle, l.triangleCount = c.triangleCount;
    l.center = c.center, l.radius = c.radius, l.coneAxis = c.coneAxis, l.coneCutoff = c.coneCutoff;
    l.sphere = glm::vec4(c.center, c.radius), l.parentSphere = glm::vec4(c.center, 2.0f * c.radius), l.parentError = 1.0f;
    m.lod.clusters.push_back(l);
  }
  for (uint32_t k = 0; k < above; ++k) {
    LodCluster l;
    l.firstTriangle = m.triangleCount() + k, l.triangleCount = 1, l.level = 1, l.error = 1.0f, l.parentError = 2.0f;
    l.radius = 1.0f, l.sphere = l.parentSphere = glm::vec4(0, 0, 0, 1);
    m.lod.clusters.push_back(l);
    m.lod.indices.insert(m.lod.indices.end(), {3 * k % 1000, 3 * k % 1000 + 1, 3 * k % 1000 + 2});
  }
  return s;
}

size_t lodRecordAt(const std::string& bytes, size_t k) { return bytes.rfind("CLOD") + 16 + 16 + 16 + 96 * k; }

}  // namespace

// The CLOD chunk is read with the meshes' arrays, in pieces: the hierarchy decoded is one thread's at any
// thread count, records checked against the one before across pieces, and of several faults (records,
// indices, the arrays before the chunk, a mesh record of the chunk) the one earliest in the file is reported.
TEST(RtrSceneParallel, TheHierarchyIsReadInPiecesAsOneThreadReadsIt) {
  const Scene s = withHierarchy(6000);
  const ClusterLod& want = s.meshes[1].lod;
  ASSERT_GT(want.clusters.size(), 2u * 4096u) << "records in several pieces";
  const std::string good = encodeRtrScene(s);
  for (unsigned threads : {1u, 2u, 3u, 8u, 0u}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    const Scene got = decode(good, threads);
    const ClusterLod& lod = got.meshes[1].lod;
    EXPECT_EQ(lod.levels, 2u);
    EXPECT_EQ(lod.indices, want.indices);
    ASSERT_EQ(lod.clusters.size(), want.clusters.size());
    EXPECT_EQ(std::memcmp(lod.clusters.data(), want.clusters.data(), want.clusters.size() * sizeof(LodCluster)), 0);
    EXPECT_EQ(encodeRtrScene(got), good);
  }
  auto poke = [](std::string& b, size_t at, uint32_t v) { std::memcpy(b.data() + at, &v, 4); };
  // The last record of the first piece covers two triangles: only the next one, in the next piece, sees it.
  const size_t k = 4095, rec = lodRecordAt(good, k);
  uint32_t first;
  std::memcpy(&first, good.data() + rec, 4);
  ASSERT_EQ(first, want.clusters[k].firstTriangle);
  std::string b = good;
  poke(b, rec + 4, 2);
  reseal(b);
  // A later record and a later index damaged too.
  poke(b, lodRecordAt(good, 8000) + 8, 0);                                    // level 0 above level 0
  const size_t indexAt = lodRecordAt(good, want.clusters.size()) + 4 * 9000;  // the indices follow the records
  poke(b, indexAt, 1u << 30);
  reseal(b);
  const std::string expect = "p.rtrscene: byte " + std::to_string(rec + 96) +
                             ": CLOD chunk: mesh 1: cluster 4096: first triangle " + std::to_string(first + 1) + " is not " +
                             std::to_string(first + 2);
  for (unsigned threads : {1u, 2u, 8u}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    EXPECT_THAT(decodeError(b, threads), HasSubstr(expect));
  }
  std::string idx = good;  // the index alone
  poke(idx, indexAt, 1u << 30);
  reseal(idx);
  EXPECT_THAT(decodeError(idx, 8),
              HasSubstr("byte " + std::to_string(indexAt) + ": CLOD chunk: mesh 1: index 1073741824 out of range"));
  // A damaged mesh record of the chunk waits for the arrays before it: a position of mesh 0 is reported.
  std::string both = good;
  poke(both, good.rfind("CLOD") + 16 + 16 + 4, 0);  // level count 0
  reseal(both);
  EXPECT_THAT(decodeError(both, 8), HasSubstr("CLOD chunk: mesh 1: level count 0"));
  const glm::vec3 p0 = s.meshes[0].positions[7];
  const size_t posAt = good.find(std::string(reinterpret_cast<const char*>(&p0), 12));
  const float nan = std::nanf("");
  std::memcpy(both.data() + posAt, &nan, 4);
  reseal(both);
  for (unsigned threads : {1u, 8u})
    EXPECT_THAT(decodeError(both, threads), HasSubstr("byte " + std::to_string(posAt) + ": mesh 0: position 7 is not finite"));
}
