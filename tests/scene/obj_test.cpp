// OBJ/MTL parser behaviour: triangulation, welding, normals, meshes per object x material, MTL fields, bad input.
#include <filesystem>
#include <fstream>
#include <map>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <zstd.h>

#include <glm/geometric.hpp>

#include "core/error.hpp"
#include "scene/load.hpp"
#include "scene/obj.hpp"

using namespace rtr;
using ::testing::HasSubstr;

namespace {

struct Parsed {
  Scene scene;
  ObjStats stats;
  std::vector<std::string> warnings;
};

Parsed parse(const std::string& obj, std::map<std::string, std::string> mtls = {}, bool zstd = false,
             float creaseDeg = LoadOptions{}.creaseDeg) {
  Parsed r;
  ObjOptions opt;
  opt.creaseDeg = creaseDeg;
  opt.warn = [&](const std::string& w) { r.warnings.push_back(w); };
  opt.threads = 2;
  auto src = memorySource(obj, "test.obj", zstd);
  r.scene = parseObj(
      *src, "test.obj",
      [&](const std::string& n) -> std::optional<std::string> {
        auto it = mtls.find(n);
        if (it == mtls.end()) return std::nullopt;
        return it->second;
      },
      opt, &r.stats);
  return r;
}

std::string errorOf(const std::string& obj, std::map<std::string, std::string> mtls = {}) {
  try {
    parse(obj, mtls);
  } catch (const Error& e) { return e.what(); }
  return "(no error)";
}

std::string compress(const std::string& s) {
  std::string out(ZSTD_compressBound(s.size()), '\0');
  size_t n = ZSTD_compress(out.data(), out.size(), s.data(), s.size(), 3);
  EXPECT_FALSE(ZSTD_isError(n));
  out.resize(n);
  return out;
}

const char* kQuad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

}  // namespace

TEST(Obj, QuadIsFanTriangulatedWithGeneratedNormals) {
  Parsed p = parse(kQuad);
  ASSERT_EQ(p.scene.meshes.size(), 1u);
  const Mesh& m = p.scene.meshes[0];
  EXPECT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  ASSERT_EQ(m.normals.size(), 4u);
  for (auto n : m.normals) EXPECT_NEAR(n.z, 1.0f, 1e-6f);
  EXPECT_TRUE(m.texcoords.empty());
  EXPECT_EQ(m.bounds.min, glm::vec3(0.0f));
  EXPECT_EQ(m.bounds.max, glm::vec3(1, 1, 0));
  EXPECT_EQ(p.stats.faces, 1u);
  EXPECT_EQ(p.stats.triangles, 2u);
  EXPECT_EQ(p.stats.verticesBeforeWeld, 6u);
  EXPECT_EQ(p.stats.verticesAfterWeld, 4u);
}

TEST(Obj, NegativeIndicesAreRelative) {
  Parsed a = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nf -3/-3/-1 -2/-2/-1 -1/-1/-1\n");
  Parsed b = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1\n");
  ASSERT_EQ(a.scene.meshes.size(), 1u);
  EXPECT_EQ(a.scene.meshes[0].positions, b.scene.meshes[0].positions);
  EXPECT_EQ(a.scene.meshes[0].texcoords, b.scene.meshes[0].texcoords);
  EXPECT_EQ(a.scene.meshes[0].indices, b.scene.meshes[0].indices);
  EXPECT_EQ(a.scene.meshes[0].texcoords[1], glm::vec2(1, 0));
}

TEST(Obj, WeldsWithinToleranceOnly) {
  // Two triangles sharing an edge, written with duplicated vertices; the copy of (1,0,0) is 5e-6 off.
  Parsed close = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1.000005 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 4 5 6\n");
  EXPECT_EQ(close.scene.meshes[0].positions.size(), 4u);
  Parsed far = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1.00003 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 4 5 6\n");
  EXPECT_EQ(far.scene.meshes[0].positions.size(), 5u);
  // Different normals keep vertices apart.
  Parsed seams = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 1 0\nf 1//1 2//1 3//1\nf 1//2 3//2 2//2\n");
  EXPECT_EQ(seams.scene.meshes[0].positions.size(), 6u);
}

TEST(Obj, GeneratedNormalsAreAreaWeighted) {
  // A big triangle in the z=0 plane and a small one in the x=0 plane share vertex 1 (the origin).
  // Smooth (--crease 180): at the default 40° the two would keep their own normals.
  Parsed p = parse("v 0 0 0\nv 4 0 0\nv 0 4 0\nv 0 0 -1\nf 1 2 3\nf 1 3 4\n", {}, false, 180.0f);
  const Mesh& m = p.scene.meshes[0];
  ASSERT_EQ(m.positions[0], glm::vec3(0.0f));
  glm::vec3 n = m.normals[0];
  // Areas 8 (normal +z) and 2 (normal -x): the sum points along (-2, 0, 8), not the unweighted (-1, 0, 1).
  glm::vec3 expect = glm::normalize(glm::vec3(-2, 0, 8));
  EXPECT_NEAR(n.x, expect.x, 1e-5f);
  EXPECT_NEAR(n.z, expect.z, 1e-5f);
}

TEST(Obj, DegenerateTrianglesAreSkippedAndCounted) {
  Parsed p = parse("v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 1 4\nf 1 2 4\n");
  EXPECT_EQ(p.stats.degenerateSkipped, 2u);
  EXPECT_EQ(p.scene.meshes[0].triangleCount(), 1u);
}

TEST(Obj, OneMeshPerObjectAndMaterial) {
  const std::string mtl = "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n";
  Parsed p = parse(
      "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
      "o A\nusemtl red\nf 1 2 3\nusemtl blue\nf 1 2 3\nusemtl red\nf 1 3 2\n"
      "o B\nf 1 2 3\n",
      {{"a.mtl", mtl}});
  ASSERT_EQ(p.scene.meshes.size(), 3u);
  EXPECT_EQ(p.scene.meshes[0].name, "A");
  EXPECT_EQ(p.scene.materials[p.scene.meshes[0].material].name, "red");
  EXPECT_EQ(p.scene.meshes[0].triangleCount(), 2u);
  EXPECT_EQ(p.scene.materials[p.scene.meshes[1].material].name, "blue");
  EXPECT_EQ(p.scene.meshes[2].name, "B");
}

TEST(Obj, WithoutGroupsEachUsemtlRunIsAnObject) {
  // Two light quads with the same material and no o/g lines must stay two meshes (two area lights).
  const std::string mtl = "newmtl light\nKe 1 1 1\n";
  Parsed p = parse(
      "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
      "usemtl light\nf 1 2 3 4\nusemtl light\nf 1 3 2\n",
      {{"a.mtl", mtl}});
  ASSERT_EQ(p.scene.meshes.size(), 2u);
  EXPECT_EQ(p.scene.meshes[0].triangleCount(), 2u);
  EXPECT_EQ(p.scene.meshes[1].triangleCount(), 1u);
  EXPECT_TRUE(p.scene.materials[0].flags & kMaterialLight);
}

TEST(Obj, MaterialFieldsTexturesAndFlags) {
  const std::string mtl =
      "# comment\nnewmtl stone\nKd 0.5 0.25 1\nKa 0.1 0.2 0.3\nKs 0.9\nNs 32\nPr 0.7\nPm 0.2\n"
      "map_Kd stone_col.png\nmap_Pr stone_r.png\nmap_Pm stone_m.png\nnorm stone_n.png\n"
      "newmtl leaves.DoubleSided\nmap_Kd leaf.png\nmap_d leaf.png\n"
      "newmtl light_fire\nKe 2 1 0.5\nmap_Ke -bm 1 fire.png\nN_mirr 0.25\nN_ior 1.5\nN_transp 0.5\n"
      "newmtl reuse\nmap_Kd stone_col.png\n";
  Parsed p = parse("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl stone\nf 1 2 3\n", {{"m.mtl", mtl}});
  const auto& ms = p.scene.materials;
  ASSERT_EQ(ms.size(), 4u);
  EXPECT_EQ(ms[0].baseColor, glm::vec3(0.5f, 0.25f, 1.0f));
  EXPECT_EQ(ms[0].kd, ms[0].baseColor);
  EXPECT_EQ(ms[0].ka, glm::vec3(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(ms[0].ks, glm::vec3(0.9f));
  EXPECT_EQ(ms[0].ns, 32.0f);
  EXPECT_FLOAT_EQ(ms[0].roughness, 0.7f);
  EXPECT_FLOAT_EQ(ms[0].metalness, 0.2f);
  EXPECT_EQ(ms[0].flags, 0u);
  // Ids at first appearance, de-duplicated: stone_col 0, stone_r 1, stone_m 2, stone_n 3, leaf 4, fire 5.
  ASSERT_EQ(p.scene.textures.size(), 6u);
  EXPECT_EQ(ms[0].textures, (std::array<uint32_t, kTextureSlotCount>{0, 1, 2, kNoTexture, 3, kNoTexture, kNoTexture}));
  EXPECT_EQ(ms[1].textures,
            (std::array<uint32_t, kTextureSlotCount>{4, kNoTexture, kNoTexture, 4, kNoTexture, kNoTexture, kNoTexture}));
  EXPECT_EQ(ms[1].flags, kMaterialAlphaMasked | kMaterialDoubleSided);
  EXPECT_EQ(ms[2].flags, kMaterialLight);
  EXPECT_EQ(ms[2].emissive, glm::vec3(2, 1, 0.5f));
  EXPECT_EQ(ms[2].ke, ms[2].emissive);
  EXPECT_EQ(ms[2].textures[uint32_t(TextureSlot::Emissive)], 5u);
  EXPECT_EQ(p.scene.textures[5].path, "fire.png");
  EXPECT_FLOAT_EQ(ms[2].mirror, 0.25f);
  EXPECT_FLOAT_EQ(ms[2].ior, 1.5f);
  EXPECT_FLOAT_EQ(ms[2].transparency, 0.5f);
  EXPECT_EQ(ms[3].textures[0], 0u);
  EXPECT_TRUE(p.scene.textures[0].srgb);
  EXPECT_EQ(p.scene.textures[0].channels, 4);
  EXPECT_FALSE(p.scene.textures[1].srgb);
  EXPECT_EQ(p.scene.textures[1].channels, 1);
  EXPECT_EQ(p.scene.textures[3].channels, 3);
  // Defaults per docs/formats.md.
  EXPECT_EQ(ms[1].ka, glm::vec3(0.5f));
  EXPECT_EQ(ms[1].ior, 1.0f);
}

TEST(Obj, TexcoordsKeptWhenPresent) {
  Parsed p = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.25 0.5\nf 1/1 2/1 3/1\n");
  ASSERT_EQ(p.scene.meshes[0].texcoords.size(), 3u);
  EXPECT_EQ(p.scene.meshes[0].texcoords[2], glm::vec2(0.25f, 0.5f));
}

TEST(Obj, CrlfAndCommentsAndLastLineWithoutNewline) {
  Parsed p = parse("# c\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\n\r\nf 1 2 3");
  EXPECT_EQ(p.scene.meshes[0].triangleCount(), 1u);
}

TEST(Obj, ZstdStreamGivesTheSameScene) {
  std::string big = "o big\n";
  for (int i = 0; i < 20000; ++i) big += "v " + std::to_string(i) + " " + std::to_string(i % 7) + " 0.5\n";
  for (int i = 1; i + 2 <= 20000; i += 2)
    big += "f " + std::to_string(i) + " " + std::to_string(i + 1) + " " + std::to_string(i + 2) + "\n";
  Parsed plain = parse(big);
  Parsed z = parse(compress(big), {}, true);
  ASSERT_EQ(plain.scene.meshes.size(), 1u);
  EXPECT_EQ(plain.scene.meshes[0].positions, z.scene.meshes[0].positions);
  EXPECT_EQ(plain.scene.meshes[0].indices, z.scene.meshes[0].indices);
  EXPECT_EQ(plain.stats.textBytes, big.size());
}

TEST(ObjErrors, TruncatedAndCorruptZstd) {
  std::string z = compress(std::string(kQuad) + std::string(1000, '#') + "\n");
  try {
    parse(z.substr(0, z.size() - 5), {}, true);
    FAIL() << "truncated stream accepted";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("test.obj"));
    EXPECT_THAT(e.what(), HasSubstr("truncated zstd"));
  }
  std::string bad = z;
  bad[0] ^= 0x55;  // breaks the frame magic
  try {
    parse(bad, {}, true);
    FAIL() << "corrupt stream accepted";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("corrupt zstd"));
    EXPECT_THAT(e.what(), HasSubstr("byte"));
  }
}

TEST(ObjErrors, IndexZeroAndOutOfRangeNameFileAndLine) {
  EXPECT_THAT(errorOf("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"), HasSubstr("test.obj:4: face position index 0"));
  EXPECT_THAT(errorOf("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n"), HasSubstr("test.obj:5: face position index 4 out of range"));
  EXPECT_THAT(errorOf("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n"), HasSubstr("test.obj:4"));
  // A texcoord or normal index that points nowhere is dropped for its face (first_look_test.cpp), not refused.
  EXPECT_THAT(errorOf("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n"), HasSubstr("test.obj:4"));
}

TEST(ObjErrors, NonFiniteCoordinates) {
  EXPECT_THAT(errorOf("v 0 0 0\nv nan 0 0\n"), HasSubstr("test.obj:2: 'v' coordinate is NaN or infinite"));
  EXPECT_THAT(errorOf("v 0 inf 0\n"), HasSubstr("test.obj:1"));
  EXPECT_THAT(errorOf("vn 0 0 1e99\n"), HasSubstr("NaN or infinite"));
  EXPECT_THAT(errorOf("v 0 0 zero\n"), HasSubstr("not a number"));
  EXPECT_THAT(errorOf("v 0 0\n"), HasSubstr("needs 3 numbers"));
}

TEST(ObjWarnings, UnknownMtlKeyAndMaterialWarnAndContinue) {
  Parsed p = parse("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl nowhere\nf 1 2 3\n",
                   {{"m.mtl", "newmtl a\nKd 1 1 1\nfrobnicate 3\nKs 0.25\n"}});
  ASSERT_EQ(p.warnings.size(), 2u);
  EXPECT_THAT(p.warnings[0], HasSubstr("m.mtl:3: unknown MTL key 'frobnicate'"));
  EXPECT_THAT(p.warnings[1], HasSubstr("nowhere"));
  EXPECT_EQ(p.scene.materials[0].ks, glm::vec3(0.25f));  // parsing went on after the unknown key
  EXPECT_EQ(p.scene.materials[p.scene.meshes[0].material].name, "nowhere");
}
