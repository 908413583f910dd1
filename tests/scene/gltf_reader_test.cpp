// The glTF reader's geometry: containers (.gltf + .bin, data URI, .glb), accessors (strides, normalized
// and quantized components, sparse, non-indexed), primitive modes, flat normals, the node hierarchy as
// instances, and the one note for animations.
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "gltf_builder.hpp"
#include "scene/gltf.hpp"
#include "scene/load.hpp"

using namespace rtr;
using rtr::test::GltfBuilder;
using ::testing::HasSubstr;

namespace {

const std::vector<glm::vec3> kTri = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};

std::string meshJson(int pos, int idx = -1, const std::string& moreAttrs = "", int mode = 4) {
  return "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":" + std::to_string(pos) + moreAttrs + "}" +
         (idx >= 0 ? ",\"indices\":" + std::to_string(idx) : "") + ",\"mode\":" + std::to_string(mode) + "}]}]";
}
const std::string kOneNode = "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]";

struct Notes {
  std::vector<std::string> notes, warnings;
  LoadOptions options() {
    LoadOptions o;
    o.note = [this](const std::string& s) { notes.push_back(s); };
    o.warn = [this](const std::string& s) { warnings.push_back(s); };
    return o;
  }
};

TEST(GltfReader, SameTriangleFromGltfBinDataUriAndGlb) {
  const auto dir = test::tempFolder("containers");
  GltfBuilder b;
  const int pos = b.floats(kTri, "VEC3");
  const int nrm = b.floats(std::vector<glm::vec3>(3, {0, 0, 1}), "VEC3");
  const int idx = b.indices({0, 1, 2});
  const std::string rest = meshJson(pos, idx, ",\"NORMAL\":" + std::to_string(nrm)) + "," + kOneNode;
  std::filesystem::copy_file(b.writeGlb(dir, "bin", rest), dir / "UPPER.GLB");  // the extension in any case
  for (const auto& file :
       {b.writeGltf(dir, "ext", rest), b.writeEmbedded(dir, "uri", rest), b.writeGlb(dir, "bin", rest), dir / "UPPER.GLB"}) {
    SCOPED_TRACE(file.string());
    const Scene s = loadScene(file);
    ASSERT_EQ(s.meshes.size(), 1u);
    EXPECT_EQ(s.meshes[0].positions, kTri);
    EXPECT_EQ(s.meshes[0].indices, (std::vector<uint32_t>{0, 1, 2}));
    EXPECT_EQ(s.meshes[0].normals[2], glm::vec3(0, 0, 1));
    EXPECT_EQ(s.meshes[0].bounds.max, glm::vec3(1, 1, 0));
    ASSERT_EQ(s.instances.size(), 1u);
    EXPECT_EQ(s.instances[0].transform, glm::mat4(1.0f));
    EXPECT_TRUE(s.materials.at(s.meshes[0].material).flags & kMaterialGltf);
    EXPECT_FALSE(s.meshes[0].clusters.empty());  // loadScene built them
  }
}

TEST(GltfReader, InterleavedStrideNormalizedAndQuantizedComponents) {
  const auto dir = test::tempFolder("interleaved");
  // Interleaved, 16 bytes a vertex: int16 position (KHR_mesh_quantization, not normalized) at 0, uint8
  // normalized uv at 8.
  std::vector<uint8_t> data(3 * 16, 0);
  const int16_t ps[3][3] = {{0, 0, 0}, {300, 0, 0}, {0, -200, 7}};
  const uint8_t uvs[3][2] = {{0, 255}, {51, 0}, {255, 102}};
  for (int i = 0; i < 3; ++i) {
    std::memcpy(&data[i * 16], ps[i], 6);
    std::memcpy(&data[i * 16 + 8], uvs[i], 2);
  }
  GltfBuilder b;
  const int v = b.view(data.data(), data.size(), "\"byteStride\":16");
  const int pos = b.accessor(v, 5122, 3, "VEC3");
  const int uv = b.accessor(v, 5121, 3, "VEC2", "\"byteOffset\":8,\"normalized\":true");
  // int8 normalized normals: -127 maps to -1.
  const int8_t ns[3][3] = {{0, 0, 127}, {0, 0, 127}, {0, -127, 0}};
  const int nv = b.view(ns, sizeof ns);
  const int nrm = b.accessor(nv, 5120, 3, "VEC3", "\"normalized\":true");
  // int8 and int16 normalized uvs (signed: max(c / 127, -1) and max(c / 32767, -1)).
  const int8_t uv1[3][2] = {{-128, -127}, {127, 64}, {0, -64}};
  const int uv1v = b.view(uv1, sizeof uv1);
  const int uv1a = b.accessor(uv1v, 5120, 3, "VEC2", "\"normalized\":true");
  const Scene s = loadScene(b.writeGlb(
      dir, "q",
      meshJson(pos, -1,
               ",\"TEXCOORD_0\":" + std::to_string(uv) + ",\"NORMAL\":" + std::to_string(nrm) +
                   ",\"TEXCOORD_1\":" + std::to_string(uv1a)) +
          ",\"extensionsUsed\":[\"KHR_mesh_quantization\"],\"extensionsRequired\":[\"KHR_mesh_quantization\"]," + kOneNode));
  const Mesh& m = s.meshes.at(0);
  EXPECT_EQ(m.positions[1], glm::vec3(300, 0, 0));
  EXPECT_EQ(m.positions[2], glm::vec3(0, -200, 7));
  EXPECT_FLOAT_EQ(m.texcoords[0].y, 1.0f);
  EXPECT_FLOAT_EQ(m.texcoords[1].x, 0.2f);
  EXPECT_FLOAT_EQ(m.texcoords[2].y, 0.4f);
  EXPECT_EQ(m.normals[2], glm::vec3(0, -1, 0));
  EXPECT_EQ(m.texcoords1[0], glm::vec2(-1.0f, -1.0f));
  EXPECT_EQ(m.texcoords1[1].x, 1.0f);
  EXPECT_FLOAT_EQ(m.texcoords1[1].y, 64.0f / 127.0f);
  EXPECT_FLOAT_EQ(m.texcoords1[2].y, -64.0f / 127.0f);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2}));  // non-indexed: in order
}

TEST(GltfReader, SparseAccessorOverridesBaseAndZeros) {
  const auto dir = test::tempFolder("sparse");
  GltfBuilder b;
  const int base = b.view(kTri.data(), 36);
  const uint16_t sIdx[2] = {0, 2};
  const glm::vec3 sVal[2] = {{5, 5, 5}, {-1, 2, 3}};
  const int iv = b.view(sIdx, sizeof sIdx), vv = b.view(sVal, sizeof sVal);
  const std::string sparse = "\"sparse\":{\"count\":2,\"indices\":{\"bufferView\":" + std::to_string(iv) +
                             ",\"componentType\":5123},\"values\":{\"bufferView\":" + std::to_string(vv) + "}}";
  const int pos = b.accessor(base, 5126, 3, "VEC3", sparse);
  const int zeroPos = b.accessor(-1, 5126, 3, "VEC3", sparse);  // no bufferView: zeros, then the sparse values
  GltfBuilder b2 = b;
  const Scene s = loadScene(b.writeGlb(dir, "a", meshJson(pos) + "," + kOneNode));
  EXPECT_EQ(s.meshes.at(0).positions, (std::vector<glm::vec3>{{5, 5, 5}, {1, 0, 0}, {-1, 2, 3}}));
  const Scene z = loadScene(b2.writeGlb(dir, "b", meshJson(zeroPos) + "," + kOneNode));
  EXPECT_EQ(z.meshes.at(0).positions, (std::vector<glm::vec3>{{5, 5, 5}, {0, 0, 0}, {-1, 2, 3}}));
}

TEST(GltfReader, StripsAndFansBecomeListsPointsAndLinesAreSkippedWithOneNote) {
  const auto dir = test::tempFolder("modes");
  GltfBuilder b;
  const int pos = b.floats(std::vector<glm::vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}}, "VEC3");
  const int nrm = b.floats(std::vector<glm::vec3>(5, {0, 0, 1}), "VEC3");
  auto load = [&](int mode, const std::string& name, Notes& n) {
    return loadScene(b.writeGlb(dir, name, meshJson(pos, -1, ",\"NORMAL\":" + std::to_string(nrm), mode) + "," + kOneNode),
                     n.options());
  };
  Notes n;
  // Strip: (0,1,2), (1,3,2), (2,3,4): every triangle keeps the first one's winding.
  EXPECT_EQ(load(5, "strip", n).meshes.at(0).indices, (std::vector<uint32_t>{0, 1, 2, 1, 3, 2, 2, 3, 4}));
  // Fan around vertex 0: (1,2,0), (2,3,0), (3,4,0).
  EXPECT_EQ(load(6, "fan", n).meshes.at(0).indices, (std::vector<uint32_t>{1, 2, 0, 2, 3, 0, 3, 4, 0}));
  EXPECT_TRUE(n.notes.empty());
  // A mesh of points and one of triangles: the points are left out with one note.
  const std::string two =
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"mode\":0},{\"attributes\":{\"POSITION\":0},\"mode\":1},"
      "{\"attributes\":{\"POSITION\":0}}]}]," +
      kOneNode;
  const Scene s = loadScene(b.writeGlb(dir, "points", two), n.options());
  EXPECT_EQ(s.meshes.size(), 1u);
  ASSERT_EQ(n.notes.size(), 1u);
  EXPECT_THAT(n.notes[0], HasSubstr("2 primitive(s) of points or lines"));
  EXPECT_THAT(n.notes[0], HasSubstr("points.glb"));
}

TEST(GltfReader, MissingNormalsGiveFlatNormals) {
  const auto dir = test::tempFolder("flat");
  GltfBuilder b;
  // Two triangles sharing an edge at a right angle: shared vertices must get each face's own normal.
  const int pos = b.floats(std::vector<glm::vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, -1}}, "VEC3");
  const int idx = b.indices({0, 1, 2, 0, 2, 3});
  const Mesh m = loadScene(b.writeGlb(dir, "f", meshJson(pos, idx) + "," + kOneNode)).meshes.at(0);
  ASSERT_EQ(m.positions.size(), 6u);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(m.normals[m.indices[c]], glm::vec3(0, 0, 1));
    EXPECT_EQ(m.normals[m.indices[3 + c]], glm::vec3(-1, 0, 0));
  }
  EXPECT_EQ(m.positions[m.indices[5]], glm::vec3(0, 0, -1));
}

TEST(GltfReader, NodeHierarchyBecomesInstancesOfOneMesh) {
  const auto dir = test::tempFolder("nodes");
  GltfBuilder b;
  const int pos = b.floats(kTri, "VEC3");
  // Node 0: translation (1,2,3) with children 1 and 2; node 1: uniform scale 2; node 2: a matrix that
  // turns 90° about z (x -> y). Both children draw mesh 0; node 3 is not in the scene.
  const std::string rest = meshJson(pos) +
                           ",\"nodes\":[{\"translation\":[1,2,3],\"children\":[1,2]},{\"scale\":[2,2,2],\"mesh\":0},"
                           "{\"matrix\":[0,1,0,0, -1,0,0,0, 0,0,1,0, 0,0,0,1],\"mesh\":0},{\"mesh\":0}],"
                           "\"scenes\":[{\"nodes\":[3]},{\"nodes\":[0]}],\"scene\":1";
  const Scene s = loadScene(b.writeGlb(dir, "h", rest));
  ASSERT_EQ(s.meshes.size(), 1u);
  ASSERT_EQ(s.instances.size(), 2u);
  auto apply = [](const glm::mat4& m, glm::vec3 p) { return glm::vec3(m * glm::vec4(p, 1)); };
  EXPECT_EQ(apply(s.instances[0].transform, {1, 0, 0}), glm::vec3(3, 2, 3));
  const glm::vec3 q = apply(s.instances[1].transform, {1, 0, 0});
  EXPECT_NEAR(q.x, 1, 1e-6);
  EXPECT_NEAR(q.y, 3, 1e-6);
  EXPECT_NEAR(q.z, 3, 1e-6);
  // A rotation quaternion: 90° about y takes +x to -z.
  const std::string rot =
      meshJson(pos) + ",\"nodes\":[{\"rotation\":[0,0.70710678,0,0.70710678],\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]";
  const glm::vec3 r = apply(loadScene(b.writeGlb(dir, "r", rot)).instances.at(0).transform, {1, 0, 0});
  EXPECT_NEAR(r.x, 0, 1e-6);
  EXPECT_NEAR(r.z, -1, 1e-6);
  EXPECT_EQ(s.bounds().max.x, 3.0f);
}

TEST(GltfReader, AtMostTenWarningsThenTheCount) {
  const auto dir = test::tempFolder("warnings");
  GltfBuilder b;
  b.floats(kTri, "VEC3");
  b.indices({0, 1, 2, 0});  // 4 indices: the last one is left out, with a warning
  std::string meshes = "\"meshes\":[";
  for (int i = 0; i < 12; ++i)
    meshes += std::string(i ? "," : "") + "{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}";
  std::string nodes = "],\"nodes\":[";
  for (int i = 0; i < 12; ++i) nodes += std::string(i ? "," : "") + "{\"mesh\":" + std::to_string(i) + "}";
  Notes n;
  const Scene s = loadScene(b.writeGlb(dir, "w", meshes + nodes + "]"), n.options());
  EXPECT_EQ(s.meshes.size(), 12u);
  ASSERT_EQ(n.warnings.size(), 11u);
  EXPECT_THAT(n.warnings[0], HasSubstr("not whole triangles"));
  EXPECT_THAT(n.warnings[10], HasSubstr("w.glb: 12 warnings, first 10 shown"));
}

TEST(GltfReader, AnimationsSkinsAndMorphTargetsGetOneNote) {
  const auto dir = test::tempFolder("anim");
  GltfBuilder b;
  const int pos = b.floats(kTri, "VEC3");
  const std::string rest =
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"targets\":[{\"POSITION\":0}]}]}],"
      "\"nodes\":[{\"mesh\":0,\"weights\":[0.5]}],\"scenes\":[{\"nodes\":[0]}],\"animations\":[{\"channels\":[],\"samplers\":[]}]";
  (void)pos;
  Notes n;
  const Scene s = loadScene(b.writeGlb(dir, "a", rest), n.options());
  EXPECT_EQ(s.meshes.at(0).positions, kTri);
  ASSERT_EQ(n.notes.size(), 1u);
  EXPECT_THAT(n.notes[0], HasSubstr("not played"));
}

TEST(GltfReader, UsedExtensionsGetANoteRequiredOnesAreRead) {
  const auto dir = test::tempFolder("ext");
  GltfBuilder b;
  const int pos = b.floats(kTri, "VEC3");
  Notes n;
  loadScene(
      b.writeGlb(dir, "e", meshJson(pos) + ",\"extensionsUsed\":[\"KHR_materials_sheen\",\"KHR_texture_transform\"]," + kOneNode),
      n.options());
  ASSERT_EQ(n.notes.size(), 1u);
  EXPECT_THAT(n.notes[0], HasSubstr("KHR_materials_sheen"));
  EXPECT_THAT(n.notes[0], ::testing::Not(HasSubstr("KHR_texture_transform")));
}

TEST(GltfReader, ParsesFromMemoryWithoutScenesUsingRootNodes) {
  GltfBuilder b;
  const int pos = b.floats(kTri, "VEC3");
  // No "scenes": the nodes that are nobody's child are drawn (node 1 is node 0's child: drawn once).
  const std::string glb = b.glb(meshJson(pos) + ",\"nodes\":[{\"children\":[1]},{\"mesh\":0}]");
  const Scene s = parseGltf({reinterpret_cast<const uint8_t*>(glb.data()), glb.size()}, "mem.glb", ".");
  EXPECT_EQ(s.instances.size(), 1u);
}

}  // namespace
