// Malformed glTF and GLB files are refused with the file's name and the JSON path (or GLB byte offset)
// of the fault; nothing is read past a buffer.
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "gltf_builder.hpp"
#include "scene/gltf.hpp"
#include "scene/load.hpp"

using namespace rtr;
using rtr::test::GltfBuilder;
using ::testing::HasSubstr;

namespace {

const std::vector<glm::vec3> kTri = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
const std::string kMesh =
    "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]";

std::string errorOf(const std::filesystem::path& file) {
  try {
    loadScene(file);
  } catch (const Error& e) { return e.what(); }
  return "(no error)";
}

std::string errorOfGlb(const std::string& bytes) {
  try {
    parseGltf({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()}, "bad.glb", ".");
  } catch (const Error& e) { return e.what(); }
  return "(no error)";
}

struct Errors : ::testing::Test {
  std::filesystem::path dir = test::tempFolder(::testing::UnitTest::GetInstance()->current_test_info()->name());
};

TEST_F(Errors, AccessorPastTheEndOfItsView) {
  GltfBuilder b;
  const int v = b.view(kTri.data(), 36);
  b.accessor(v, 5126, 3, "VEC3", "\"byteOffset\":4");  // 4 + 36 > 36
  EXPECT_THAT(errorOf(b.writeGlb(dir, "a", kMesh)),
              HasSubstr("a.glb: /accessors/0: byteOffset 4 + 36 bytes of elements run past the end of bufferView 0 (36 bytes)"));
  GltfBuilder c;
  c.accessor(c.view(kTri.data(), 36), 5126, 4, "VEC3");  // one element too many
  EXPECT_THAT(errorOf(c.writeGltf(dir, "b", kMesh)), HasSubstr("b.gltf: /accessors/0: byteOffset 0 + 48 bytes"));
}

TEST_F(Errors, OverflowingOffsetsAndLengths) {
  GltfBuilder b;
  b.accessor(b.view(kTri.data(), 36), 5126, 3, "VEC3", "\"byteOffset\":18446744073709551615");
  EXPECT_THAT(errorOf(b.writeGlb(dir, "a", kMesh)), HasSubstr("a.glb: /accessors/0: byteOffset 18446744073709551615"));
  GltfBuilder c;
  c.view(kTri.data(), 36);
  c.views[0] = "{\"buffer\":0,\"byteOffset\":18446744073709551600,\"byteLength\":32}";
  c.accessor(0, 5126, 2, "VEC3");
  EXPECT_THAT(errorOf(c.writeGlb(dir, "b", kMesh)),
              HasSubstr("b.glb: /bufferViews/0: byteOffset 18446744073709551600 + byteLength 32 run past"));
  GltfBuilder d;
  d.accessor(d.view(kTri.data(), 36), 5126, 4294967296ull, "VEC3");
  EXPECT_THAT(errorOf(d.writeGlb(dir, "c", kMesh)), HasSubstr("c.glb: /accessors/0/count: 4294967296 is not an element count"));
  GltfBuilder e;  // a buffer claiming more than the file has
  e.accessor(e.view(kTri.data(), 36), 5126, 3, "VEC3");
  const std::string json = e.json(kMesh, "e.bin");
  test::writeFile(dir / "e.bin", e.bin.substr(0, 20));
  test::writeFile(dir / "e.gltf", json);
  EXPECT_THAT(errorOf(dir / "e.gltf"),
              HasSubstr("e.gltf: /buffers/0/byteLength: 36 bytes, but the buffer's data has only 20 bytes"));
}

TEST_F(Errors, BadStride) {
  GltfBuilder b;
  b.accessor(b.view(kTri.data(), 36, "\"byteStride\":6"), 5126, 3, "VEC3");
  EXPECT_THAT(errorOf(b.writeGlb(dir, "a", kMesh)), HasSubstr("a.glb: /bufferViews/0/byteStride: 6 is not a byte stride"));
  GltfBuilder c;
  c.accessor(c.view(kTri.data(), 36, "\"byteStride\":8"), 5126, 3, "VEC3");
  EXPECT_THAT(errorOf(c.writeGlb(dir, "b", kMesh)),
              HasSubstr("b.glb: /bufferViews/0/byteStride: 8 is less than the 12 bytes of one element"));
}

TEST_F(Errors, IndexOutOfRangeAndWrongTypes) {
  GltfBuilder b;
  b.floats(kTri, "VEC3");
  b.indices({0, 1, 3});
  const std::string mesh =
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],\"nodes\":[{\"mesh\":0}]";
  EXPECT_THAT(errorOf(b.writeGlb(dir, "a", mesh)),
              HasSubstr("a.glb: /meshes/0/primitives/0/indices: index 3 (element 2) is not below the vertex count 3"));
  GltfBuilder c;
  c.floats(std::vector<glm::vec2>{{0, 0}, {1, 0}, {0, 1}}, "VEC2");
  EXPECT_THAT(errorOf(c.writeGlb(dir, "b", kMesh)), HasSubstr("b.glb: /accessors/0/type: 'VEC2' where VEC3 is expected"));
  GltfBuilder d;
  d.floats(kTri, "VEC3");
  EXPECT_THAT(
      errorOf(d.writeGlb(dir, "c", "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":7}}]}],\"nodes\":[{\"mesh\":0}]")),
      HasSubstr("c.glb: /meshes/0/primitives/0/attributes/POSITION: 7 is not one of the 1 accessors"));
}

TEST_F(Errors, BadGlbContainer) {
  GltfBuilder b;
  b.floats(kTri, "VEC3");
  const std::string good = b.glb(kMesh);
  EXPECT_EQ(errorOfGlb(good), "(no error)");
  std::string longChunk = good;
  const uint32_t huge = 1u << 30;
  std::memcpy(&longChunk[12], &huge, 4);
  EXPECT_THAT(errorOfGlb(longChunk), HasSubstr("bad.glb: byte 12: chunk 0's length 1073741824 runs past the end of the GLB"));
  std::string longFile = good;
  const uint32_t more = uint32_t(good.size() + 1);
  std::memcpy(&longFile[8], &more, 4);
  EXPECT_THAT(errorOfGlb(longFile), HasSubstr("bad.glb: byte 8: the GLB header's length"));
  std::string v1 = good;
  v1[4] = 1;
  EXPECT_THAT(errorOfGlb(v1), HasSubstr("bad.glb: byte 4: GLB version 1"));
  EXPECT_THAT(errorOfGlb(good.substr(0, 10)), HasSubstr("bad.glb: byte 0: a GLB header needs 12 bytes"));
  // The BIN chunk cut short: the header length still says the whole size.
  std::string cut = good.substr(0, good.size() - 8);
  const uint32_t cutLen = uint32_t(cut.size());
  std::memcpy(&cut[8], &cutLen, 4);
  EXPECT_THAT(errorOfGlb(cut), HasSubstr("bad.glb: byte"));
  EXPECT_THAT(errorOfGlb(cut), HasSubstr("runs past the end of the GLB"));
}

TEST_F(Errors, UnknownRequiredExtensionIsNamed) {
  GltfBuilder b;
  b.floats(kTri, "VEC3");
  EXPECT_THAT(
      errorOf(b.writeGlb(dir, "a",
                         kMesh + ",\"extensionsRequired\":[\"KHR_texture_transform\",\"KHR_materials_pbrSpecularGlossiness\"]")),
      HasSubstr(
          "a.glb: /extensionsRequired/1: the file requires extension 'KHR_materials_pbrSpecularGlossiness', which rtr does not support"));
}

TEST_F(Errors, BadBase64AndMissingBuffer) {
  GltfBuilder b;
  b.floats(kTri, "VEC3");
  test::writeFile(dir / "a.gltf", b.json(kMesh, "data:application/octet-stream;base64,AAA*AAAA"));
  EXPECT_THAT(errorOf(dir / "a.gltf"), HasSubstr("a.gltf: /buffers/0/uri: the data URI's base64 payload is not valid base64"));
  test::writeFile(dir / "b.gltf", b.json(kMesh, "nothere.bin"));
  EXPECT_THAT(errorOf(dir / "b.gltf"), HasSubstr("b.gltf: /buffers/0/uri:"));
  EXPECT_THAT(errorOf(dir / "b.gltf"), HasSubstr("nothere.bin"));
  test::writeFile(dir / "c.gltf", b.json(kMesh, ""));  // no uri in a .gltf: no GLB BIN chunk to take
  EXPECT_THAT(errorOf(dir / "c.gltf"), HasSubstr("c.gltf: /buffers/0: has no uri and is not the GLB's BIN chunk"));
}

TEST_F(Errors, CyclesVersionsAndJson) {
  GltfBuilder b;
  b.floats(kTri, "VEC3");
  EXPECT_THAT(errorOf(b.writeGlb(dir, "a",
                                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
                                 "\"nodes\":[{\"mesh\":0,\"children\":[1]},{\"children\":[0]}],\"scenes\":[{\"nodes\":[0]}]")),
              HasSubstr("a.glb: /nodes/0: the node is reached twice"));
  test::writeFile(dir / "b.gltf", "{\"asset\":{\"version\":\"1.0\"}}");
  EXPECT_THAT(errorOf(dir / "b.gltf"), HasSubstr("b.gltf: /asset/version: glTF version '1.0' (rtr reads glTF 2.0)"));
  test::writeFile(dir / "c.gltf", "{\"asset\":{\"version\":\"2.0\"},");
  EXPECT_THAT(errorOf(dir / "c.gltf"), HasSubstr("c.gltf: not valid JSON"));
  test::writeFile(dir / "d.gltf", "{\"asset\":{\"version\":\"2.0\"}}");
  EXPECT_THAT(errorOf(dir / "d.gltf"), HasSubstr("d.gltf: the scene has no triangles to draw"));
  test::writeFile(dir / "e.gltf", "{\"asset\":{\"version\":\"2.0\"},\"nodes\":{\"mesh\":0}}");
  EXPECT_THAT(errorOf(dir / "e.gltf"), HasSubstr("e.gltf: /nodes: expected an array"));
}

TEST_F(Errors, NonFinitePositions) {
  GltfBuilder b;
  b.floats(std::vector<glm::vec3>{{0, 0, 0}, {std::numeric_limits<float>::infinity(), 0, 0}, {0, 1, 0}}, "VEC3");
  EXPECT_THAT(errorOf(b.writeGlb(dir, "a", kMesh)),
              HasSubstr("a.glb: /meshes/0/primitives/0/attributes: POSITION element 1 is not finite"));
  // Found by fuzz_gltf: a coordinate of 4.5e30 made clustering lose the triangle (squared lengths overflow).
  GltfBuilder c;
  c.floats(std::vector<glm::vec3>{{0, 0, 0}, {2, 0, 4.5e30f}, {0, 1, 0}}, "VEC3");
  EXPECT_THAT(errorOf(c.writeGlb(dir, "b", kMesh)),
              HasSubstr("b.glb: /meshes/0/primitives/0/attributes: POSITION element 1 has a coordinate beyond"));
  GltfBuilder d;
  d.floats(std::vector<glm::vec3>{{0, 0, 0}, {2, 0, std::nanf("")}, {0, 1, 0}}, "VEC3");
  EXPECT_THAT(errorOf(d.writeGlb(dir, "c", kMesh)),
              HasSubstr("c.glb: /meshes/0/primitives/0/attributes: POSITION element 1 is not finite"));
}

}  // namespace
