// .rtrscene version 5 stores everything the scene model holds (glTF's instances, samplers, uv transforms,
// attributes, light kinds) and refuses damage in the new records; files of versions 1-4 load as before.
#include <cmath>
#include <cstring>
#include <limits>
#include <set>

#include <glm/gtc/matrix_transform.hpp>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "scene/binio.hpp"
#include "scene/clusters.hpp"
#include "scene/rtrscene.hpp"
#include "scene_compare.hpp"
#include "test_paths.hpp"

using namespace rtr;
using ::testing::HasSubstr;

namespace {

// A glTF-like scene using every field version 5 adds, each with a value no default has.
Scene rich() {
  Scene s;
  Texture base{"tex/base.png", true, 4};
  base.sampler = {Wrap::ClampToEdge, Wrap::MirroredRepeat, true, false, true};
  Texture rough{"tex/mr.png", false, 1}, metal{"tex/mr.png", false, 1};
  rough.sourceChannel = 2;
  metal.sourceChannel = 3;
  metal.sampler.nearestMin = true;
  s.textures = {base, rough, metal};
  Material m;
  m.name = "gltf";
  m.flags = kMaterialGltf | kMaterialBlend | kMaterialDoubleSided;
  m.baseColor = {0.8f, 0.6f, 0.4f};
  m.opacity = 0.25f;
  m.alphaCutoff = 0.3f;
  m.normalScale = 0.7f;
  m.occlusionStrength = 0.4f;
  m.textures = {0, 1, 2, kNoTexture, kNoTexture, kNoTexture, 1};
  m.uv[0] = {{0.5f, 0.25f}, 0.3f, {2.0f, 3.0f}, 1};
  m.uv[6].texCoord = 1;
  Material unlit;
  unlit.name = "unlit";
  unlit.flags = kMaterialUnlit | kMaterialAlphaMasked;
  s.materials = {m, unlit};
  Mesh quad;
  quad.name = "quad";
  quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  quad.normals.assign(4, glm::vec3(0, 0, 1));
  quad.texcoords = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  quad.texcoords1 = {{0.5f, 0.5f}, {0.75f, 0.5f}, {0.8125f, 0.6875f}, {0.5f, 0.75f}};
  quad.tangents = {{1, 0, 0, 1}, {1, 0, 0, 1}, {1, 0, 0, -1}, {1, 0, 0, 1}};
  quad.colors = {{1, 0, 0, 1}, {0, 1, 0, 0.5f}, {0, 0, 1, 0.25f}, {0.375f, 0.625f, 0.125f, 1}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  Mesh tri;
  tri.name = "tri";
  tri.material = 1;
  tri.positions = {{0, 0, 0}, {0, 0, 1}, {0, 1, 0}};
  tri.normals.assign(3, glm::vec3(1, 0, 0));
  tri.indices = {0, 1, 2};
  s.meshes = {quad, tri};
  for (Mesh& mesh : s.meshes)
    for (const glm::vec3& p : mesh.positions) mesh.bounds.extend(p);
  buildMissingClusters(s);
  glm::mat4 turned = glm::rotate(glm::translate(glm::mat4(1.0f), {3, 0, -2}), 0.7f, glm::vec3(0, 1, 0));
  s.instances = {{0, glm::mat4(1.0f)}, {0, turned}, {1, glm::scale(glm::mat4(1.0f), {2, 2, 2})}};
  s.defaultView = CameraPose{{1, 2, 3}, 30, -5};
  s.defaultFovYDeg = 39.6f;
  Light point;
  point.position = {0, 3, 0};
  point.falloff = true;
  point.range = 8;
  Light spot;
  spot.kind = Light::Kind::Spot;
  spot.position = {0, 4, 0};
  spot.color = {10, 9, 8};
  spot.direction = glm::normalize(glm::vec3(0.2f, -1, 0.1f));
  spot.innerConeCos = 0.9f;
  spot.outerConeCos = 0.7f;
  spot.range = 12;
  Light sun;
  sun.kind = Light::Kind::Directional;
  sun.direction = {0, -1, 0};
  sun.color = {3, 3, 2};
  Light area;
  area.kind = Light::Kind::Area;
  area.corner = {-1, 5, -1};
  area.edge1 = {2, 0, 0};
  area.edge2 = {0, 0, 2};
  area.normal = {0, -1, 0};
  s.lights = {point, spot, sun, area};
  return s;
}

const std::span<const uint8_t> span(const std::string& b) { return {reinterpret_cast<const uint8_t*>(b.data()), b.size()}; }

std::string decodeError(const std::string& bytes, unsigned threads = 1) {
  try {
    decodeRtrScene(span(bytes), "v5.rtrscene", threads);
  } catch (const Error& e) { return e.what(); }
  return "(no error)";
}

void reseal(std::string& b) {
  const uint64_t sum = pieceChecksum64(span(b).subspan(80));
  std::memcpy(b.data() + 40, &sum, 8);
}

template <class T>
std::string patched(const std::string& good, size_t at, T value) {
  std::string b = good;
  std::memcpy(b.data() + at, &value, sizeof value);
  reseal(b);
  return b;
}

// Where a run of floats lies in the file (each value below occurs once).
size_t find(const std::string& bytes, std::initializer_list<float> values) {
  std::string pattern;
  for (float f : values) pattern.append(reinterpret_cast<const char*>(&f), 4);
  const size_t at = bytes.find(pattern);
  EXPECT_NE(at, std::string::npos);
  EXPECT_EQ(bytes.find(pattern, at + 1), std::string::npos);
  return at;
}

}  // namespace

TEST(RtrSceneV5, KeepsEverythingTheSceneModelHolds) {
  const Scene want = rich();
  const std::string bytes = encodeRtrScene(want);
  EXPECT_EQ(bytes[8], kRtrSceneVersion);
  EXPECT_EQ(bytes.size() % 16, 0u);
  for (unsigned threads : {1u, 3u}) {
    const Scene got = decodeRtrScene(span(bytes), "v5.rtrscene", threads);
    test::expectSameScene(want, got);
    EXPECT_EQ(encodeRtrScene(got), bytes);
  }
}

// Files written by builds of versions 1, 3 and 4 (the committed fuzz seeds) load, and encoding what they
// decode to in their own version gives back their bytes; a scene that all versions can hold decodes the
// same from each.
TEST(RtrSceneV5, OlderVersionsStillLoadAsBefore) {
  const auto seeds = test::sourceDir() / "tests/fuzz/corpus/fuzz_rtrscene";
  std::set<uint32_t> versions;
  for (const char* f :
       {"cornell_box.rtrscene", "textured.rtrscene", "cube_backplane-v3.rtrscene", "cube_backplane-v4.rtrscene"}) {
    SCOPED_TRACE(f);
    const auto raw = readFileBytes(seeds / f);
    const std::string bytes(raw.begin(), raw.end());
    uint32_t version;
    std::memcpy(&version, bytes.data() + 8, 4);
    versions.insert(version);
    EXPECT_EQ(encodeRtrScene(decodeRtrScene(span(bytes), f), version), bytes);
  }
  EXPECT_EQ(versions, (std::set<uint32_t>{1, 3, 4}));
  Scene s = rich();  // less what only version 5 stores
  s.instances.clear();
  s.defaultFovYDeg = 0.0f;
  s.lights = {s.lights[0], s.lights[3]};
  s.lights[0].range = 0.0f;
  for (Texture& t : s.textures) t.sampler = {}, t.sourceChannel = 0;
  for (Material& m : s.materials) {
    m = Material{.name = m.name, .flags = m.flags & 7u, .textures = m.textures};
    m.textures[6] = kNoTexture;
  }
  for (Mesh& m : s.meshes) m.texcoords1.clear(), m.tangents.clear(), m.colors.clear();
  const Scene current = decodeRtrScene(span(encodeRtrScene(s)), "v5");
  for (uint32_t v = 1; v <= 4; ++v) {
    SCOPED_TRACE("version " + std::to_string(v));
    Scene want = current, from = s;
    if (v < 2) want.lights.clear(), from.lights.clear();
    if (v < 3)
      for (Mesh& m : want.meshes) m.clusters.clear();
    test::expectSameScene(want, decodeRtrScene(span(encodeRtrScene(from, v)), "old"));
  }
}

TEST(RtrSceneV5, OlderVersionsRefuseWhatOnlyVersion5Stores) {
  Scene s = rich();
  EXPECT_THROW(
      try { encodeRtrScene(s, 4); } catch (const Error& e) {
        EXPECT_THAT(e.what(), HasSubstr("cannot encode .rtrscene version 4 with instances"));
        throw;
      },
      Error);
  // A version 4 file with a light kind only version 5 knows is refused.
  Scene one;
  one.lights.push_back(Light{});
  const std::string v4 = patched(encodeRtrScene(one, 4), 80, uint32_t(Light::Kind::Spot));
  EXPECT_THAT(decodeError(v4), HasSubstr("v5.rtrscene: byte 80: unknown light kind 3"));
  // Textures still in memory are never silently dropped.
  s.textures[0].bytes = std::make_shared<std::vector<uint8_t>>(8, 0);
  EXPECT_THROW(encodeRtrScene(s), Error);
}

TEST(RtrSceneV5, RefusesDamageInTheNewRecords) {
  const std::string good = encodeRtrScene(rich());
  ASSERT_EQ(decodeError(good), "(no error)");
  // Layout (docs/rtrscene-format.md): header 80, 4 lights of 104 bytes (pad16: 496), 3 instances of 80.
  const size_t spot = 80 + 104, instances = 496, textures = instances + 3 * 80;
  struct Case {
    std::string bytes, message;
  };
  const Case cases[] = {
      {patched(good, 68, uint32_t(1) << 28), "byte 68: instance count 268435456 cannot fit in the file"},
      {patched(good, 72, 200.0f), "byte 72: field of view 200"},
      {patched(good, 76, uint32_t(1)), "byte 76: reserved field is not 0"},
      {patched(good, spot, uint32_t(5)), "byte 184: unknown light kind 5"},
      {patched(good, spot + 92, 1.5f), "byte 184: light: cone cosine outside -1..1"},
      {patched(good, spot + 96, 0.95f), "byte 184: light: outer cone narrower than the inner one"},
      {patched(good, spot + 80, 3.0f), "byte 184: light: direction is not a unit vector"},
      {patched(good, spot + 100, -1.0f), "byte 184: light: negative range"},
      {patched(good, spot + 100, std::numeric_limits<float>::infinity()), "byte 284: a light is not finite"},
      {patched(good, instances + 80, uint32_t(2)), "byte 576: instance of mesh 2: out of range (2 meshes)"},
      {patched(good, instances + 84, uint32_t(1)), "byte 580: reserved instance field is not 0"},
      {patched(good, instances + 80 + 16 + 4 * 13, std::nanf("")), "byte 644: an instance transform is not finite"},
      {patched(good, textures + 2, uint8_t(1)), "texture source channel 1 for 4 channels"},
      {patched(good, textures + 3, uint8_t(3)), "unknown texture wrap mode 3"},
      {patched(good, textures + 5, uint8_t(8)), "unknown texture filter flags"},
      {patched(good, find(good, {0.5f, 0.25f, 0.3f, 2.0f, 3.0f}) + 20, uint32_t(2)), "uv set 2 is neither 0 nor 1"},
      {patched(good, find(good, {0.25f, 0.3f, 0.7f, 0.4f}) + 8, std::nanf("")), "a material factor is not finite"},
      {patched(good, find(good, {0.8125f, 0.6875f}) + 4, std::nanf("")), "mesh 0: a second-set texcoord is not finite"},
      {patched(good, find(good, {1, 0, 0, -1}) + 12, -std::numeric_limits<float>::infinity()), "mesh 0: a tangent is not finite"},
      {patched(good, find(good, {0.375f, 0.625f, 0.125f}), std::nanf("")), "mesh 0: a vertex colour is not finite"},
  };
  for (const Case& c : cases)
    for (unsigned threads : {1u, 4u}) EXPECT_THAT(decodeError(c.bytes, threads), HasSubstr(c.message));
}
