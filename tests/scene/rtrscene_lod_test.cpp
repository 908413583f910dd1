// .rtrscene version 6's CLOD chunk: the cluster hierarchy round-trips bit for bit, version 5 files still
// load (without one), and a damaged chunk is refused with its byte offset, before the checksum hides it.
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "core/error.hpp"
#include "scene/cluster_lod.hpp"
#include "scene/clusters.hpp"
#include "scene/binio.hpp"
#include "scene/rtrscene.hpp"

namespace rtr {
namespace {

// A wavy grid (open, so its border is locked and the hierarchy stops at a few roots).
Scene wavyGrid(uint32_t n) {
  Scene s;
  s.materials.push_back({});
  Mesh m;
  m.name = "grid";
  for (uint32_t y = 0; y <= n; ++y)
    for (uint32_t x = 0; x <= n; ++x) m.positions.push_back({float(x), 0.3f * std::sin(0.7f * x) * std::cos(0.5f * y), float(y)});
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      const uint32_t a = y * (n + 1) + x;
      m.indices.insert(m.indices.end(), {a, a + n + 1, a + 1, a + 1, a + n + 1, a + n + 2});
    }
  m.normals.assign(m.positions.size(), {0, 1, 0});
  for (const glm::vec3& p : m.positions) m.bounds.extend(p);
  s.meshes.push_back(m);
  s.meshes.push_back(m);  // a second mesh without a hierarchy
  s.meshes[1].name = "plain";
  buildMissingClusters(s);
  s.meshes[0].lod = buildClusterLod(s.meshes[0]);
  return s;
}

std::span<const uint8_t> span(const std::string& b) { return {reinterpret_cast<const uint8_t*>(b.data()), b.size()}; }

// The offset of the chunk's body in an encoded file.
size_t bodyAt(const std::string& bytes) {
  const size_t at = bytes.rfind("CLOD");
  EXPECT_NE(at, std::string::npos);
  return at + 16;
}

// Payload size and checksum made right again after an edit, so that the chunk's own checks must find it
// (the checksum would catch any edit; fuzzing builds skip it, and a writer's bug would pass it).
void reseal(std::string& b) {
  const uint64_t payload = b.size() - 80;
  const uint64_t sum = pieceChecksum64({reinterpret_cast<const uint8_t*>(b.data()) + 80, payload});
  std::memcpy(b.data() + 32, &payload, 8);
  std::memcpy(b.data() + 40, &sum, 8);
}

void expectRefused(std::string bad, const std::string& expect) {
  reseal(bad);
  try {
    decodeRtrScene(span(bad), "bad.rtrscene");
    ADD_FAILURE() << "accepted: " << expect;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.rtrscene"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
  }
}

TEST(RtrSceneLod, RoundTripsBitForBit) {
  const Scene want = wavyGrid(60);
  ASSERT_GE(want.meshes[0].lod.levels, 3u);
  const std::string bytes = encodeRtrScene(want);
  EXPECT_EQ(bytes.size() % 16, 0u);
  EXPECT_EQ(bytes.rfind("CLOD") % 16, 0u);
  for (unsigned threads : {1u, 3u}) {
    const Scene got = decodeRtrScene(span(bytes), "lod.rtrscene", threads);
    const ClusterLod &a = want.meshes[0].lod, &b = got.meshes[0].lod;
    EXPECT_EQ(got.meshes[1].lod.levels, 0u);
    EXPECT_EQ(a.levels, b.levels);
    EXPECT_EQ(a.indices, b.indices);
    ASSERT_EQ(a.clusters.size(), b.clusters.size());
    EXPECT_EQ(std::memcmp(a.clusters.data(), b.clusters.data(), a.clusters.size() * sizeof(LodCluster)), 0);
  }
  // Encoded again: the same bytes.
  EXPECT_EQ(encodeRtrScene(decodeRtrScene(span(bytes), "lod.rtrscene")), bytes);
}

TEST(RtrSceneLod, OlderVersionsLoadWithoutIt) {
  const Scene s = wavyGrid(20);
  const std::string v5 = encodeRtrScene(s, 5);
  EXPECT_EQ(v5.find("CLOD"), std::string::npos);
  EXPECT_EQ(decodeRtrScene(span(v5), "v5.rtrscene").meshes[0].lod.levels, 0u);
  Scene none = s;
  none.meshes[0].lod = {};
  EXPECT_EQ(encodeRtrScene(none).size(), v5.size()) << "no hierarchy: no chunk";
}

// Each damage is refused naming the file, the byte offset and what is wrong.
TEST(RtrSceneLod, DamageIsRefusedWithItsOffset) {
  const std::string good = encodeRtrScene(wavyGrid(40));
  const size_t body = bodyAt(good), mesh = body + 16, cluster0 = mesh + 16;
  const Scene s = decodeRtrScene(span(good), "g");
  const size_t above = cluster0 + 96 * s.meshes[0].clusters.size();  // the first cluster above level 0
  struct Case {
    size_t at;
    uint32_t value;
    std::string expect;
  };
  const uint32_t inf = 0x7F800000;  // +infinity as float bits
  const std::string c = "CLOD chunk: mesh 0: cluster ";
  const std::string k = std::to_string(s.meshes[0].clusters.size());
  const std::vector<Case> cases = {
      {mesh, 7, "byte " + std::to_string(mesh) + ": CLOD chunk: mesh 7 out of range"},
      {mesh + 4, 0, "byte " + std::to_string(mesh + 4) + ": CLOD chunk: mesh 0: level count 0"},
      {cluster0 + 4, 3, "byte " + std::to_string(cluster0) + ": " + c + "0: level 0 must be"},
      {above, 5, "byte " + std::to_string(above) + ": " + c + k + ": first triangle 5"},
      {above + 4, 200, "byte " + std::to_string(above + 4) + ": " + c + k + ": triangle count 200"},
      {above + 8, 0, "byte " + std::to_string(above + 8) + ": " + c + k + ": level 0 not in"},
      {above + 12, inf, "byte " + std::to_string(above + 12) + ": CLOD chunk: a cluster's error is not finite"},
      {above + 80, 0, "byte " + std::to_string(above + 80) + ": " + c + k + ": parent error not above"},
      {cluster0 + 96 * s.meshes[0].lod.clusters.size(), 0x00FFFFFF, "CLOD chunk: mesh 0: index 16777215 out of range"},
      {body - 16, 0x54584554 /* "TEXT" */, "byte " + std::to_string(body - 16) + ": unknown chunk 'TEXT'"},
      {body - 8, 1u << 30, "byte " + std::to_string(body - 8) + ": chunk 'CLOD' of 1073741824 bytes: the file ends after"},
  };
  for (const Case& e : cases) {
    std::string bad = good;
    std::memcpy(bad.data() + e.at, &e.value, 4);
    expectRefused(bad, e.expect);
  }
  // A repeated chunk.
  expectRefused(good + good.substr(body - 16),
                "byte " + std::to_string(good.size()) + ": chunk 'CLOD' repeated (first at byte " + std::to_string(body - 16));
}

}  // namespace
}  // namespace rtr
