// The baked-format loaders refuse damaged files with the file, the byte offset and what is wrong.
#include <cmath>
#include <cstring>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "scene/binio.hpp"
#include "scene/course.hpp"
#include "scene/rtrscene.hpp"

using namespace rtr;
using ::testing::HasSubstr;

namespace {

Scene sample() {
  Scene s;
  s.textures.push_back({"t-tex/a.png", true, 4});
  Material m;
  m.name = "stone";
  m.textures[0] = 0;
  s.materials.push_back(m);
  Mesh mesh;
  mesh.name = "tri";
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.normals.assign(3, glm::vec3(0, 0, 1));
  mesh.texcoords = {{0, 0}, {1, 0}, {0, 1}};
  mesh.indices = {0, 1, 2};
  for (auto& p : mesh.positions) mesh.bounds.extend(p);
  s.meshes.push_back(mesh);
  return s;
}

std::string courseError(const std::string& bytes) {
  try {
    decodeCourseMesh({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()}, "x.comp5892mesh");
  } catch (const Error& e) { return e.what(); }
  return "(no error)";
}

std::string rtrError(const std::string& bytes) {
  try {
    decodeRtrScene({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()}, "x.rtrscene");
  } catch (const Error& e) { return e.what(); }
  return "(no error)";
}

void put32(std::string& b, size_t at, uint32_t v) { std::memcpy(b.data() + at, &v, 4); }

// Re-seals an edited .rtrscene so that the structural checks behind the checksum get exercised.
void reseal(std::string& b) {
  uint64_t sum = pieceChecksum64({reinterpret_cast<const uint8_t*>(b.data()) + 80, b.size() - 80});
  std::memcpy(b.data() + 40, &sum, 8);
}

}  // namespace

// Course layout of sample(): header 32, T at 32, path len at 36, path (12) at 40, cs 52, ch 53, M at 54,
// ids 58..81, mesh count 82, material 86, V 90, I 94, positions from 98, normals 134, texcoords 170, indices 194.
TEST(CourseLoader, AcceptsTheSampleAndRefusesDamage) {
  const std::string good = encodeCourseMesh(sample());
  ASSERT_EQ(good.size(), 206u);
  EXPECT_EQ(courseError(good), "(no error)");
  EXPECT_THAT(courseError(good.substr(0, 100)),
              HasSubstr("x.comp5892mesh: byte 90: mesh 0: 3 vertices and 3 indices cannot fit"));
  EXPECT_THAT(courseError(good + "x"), HasSubstr("1 bytes after the last mesh"));
  std::string b = good;
  b[3] = 'X';
  EXPECT_THAT(courseError(b), HasSubstr("byte 0: not a .comp5892mesh file"));
  b = good;
  b[27] = 'x';
  EXPECT_THAT(courseError(b), HasSubstr("byte 16: unsupported variant"));
  b = good;
  put32(b, 36, 40000);
  EXPECT_THAT(courseError(b), HasSubstr("byte 36: texture path length 40000"));
  b = good;
  put32(b, 32, 0x7FFFFFFF);
  EXPECT_THAT(courseError(b), HasSubstr("byte 32: texture count 2147483647 cannot fit"));
  b = good;
  put32(b, 58, 5);
  EXPECT_THAT(courseError(b), HasSubstr("byte 58: texture index 5 out of range"));
  b = good;
  put32(b, 86, 1);
  EXPECT_THAT(courseError(b), HasSubstr("byte 86: mesh 0: material index 1 out of range"));
  b = good;
  put32(b, 90, 0x10000000);
  EXPECT_THAT(courseError(b), HasSubstr("cannot fit"));
  b = good;
  put32(b, 198, 3);
  EXPECT_THAT(courseError(b), HasSubstr("byte 198: mesh 0: index 3 out of range"));
  b = good;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(b.data() + 110, &nan, 4);
  EXPECT_THAT(courseError(b), HasSubstr("byte 110: mesh 0: position 1 is not finite"));
  b = good;
  b[52] = 7;
  EXPECT_THAT(courseError(b), HasSubstr("byte 52: texture colour space 7"));
}

// Version 4's layout (the offsets below); version 5's new records: rtrscene_v5_test.cpp.
TEST(RtrSceneLoader, ChecksumSizeAndStructure) {
  const std::string good = encodeRtrScene(sample(), 4);
  EXPECT_EQ(rtrError(good), "(no error)");
  EXPECT_EQ(good.size() % 16, 0u);
  std::string b = good;
  b[good.size() - 20] ^= 1;
  EXPECT_THAT(rtrError(b), HasSubstr("x.rtrscene: byte 40: checksum mismatch"));
  EXPECT_THAT(rtrError(good.substr(0, good.size() - 16)), HasSubstr("byte 32: payload size"));
  EXPECT_THAT(rtrError(good.substr(0, 30)), HasSubstr("file ends inside the header"));
  b = good;
  put32(b, 8, 99);
  EXPECT_THAT(rtrError(b), HasSubstr("byte 8: unsupported version 99"));
  b = good;
  put32(b, 24, 0x40000000);
  reseal(b);
  EXPECT_THAT(rtrError(b), HasSubstr("byte 24: mesh count 1073741824 cannot fit"));
  // The last mesh's 16-bit indices (padded to 16) sit before its 16-byte cluster header (no clusters):
  // the third index is at size-32+4.
  b = good;
  b[good.size() - 28] = 9;
  reseal(b);
  EXPECT_THAT(rtrError(b), HasSubstr("mesh 0: index 9 out of range"));
  // Texture table at 80 (4 + 4 + 11 bytes, padded to 112); the material at 112: flags, name (4 + 8),
  // 24 floats, then the texture ids at 224.
  b = good;
  put32(b, 224, 3);
  reseal(b);
  EXPECT_THAT(rtrError(b), HasSubstr("texture index 3 out of range"));
  b = good;
  put32(b, 116, 50000);
  reseal(b);
  EXPECT_THAT(rtrError(b), HasSubstr("byte 116: a material name length 50000 is not below 32768"));
}
