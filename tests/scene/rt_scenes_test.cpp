// The small ray-tracer scenes in assets-src/rt load and follow the course conventions (docs/formats.md).
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "scene/load.hpp"
#include "test_paths.hpp"

using namespace rtr;

namespace {

const std::filesystem::path kRt = rtr::test::sourceDir() / "assets-src/rt";

glm::vec3 firstFaceNormal(const Mesh& m) {
  glm::vec3 a = m.positions[m.indices[0]], b = m.positions[m.indices[1]], c = m.positions[m.indices[2]];
  return glm::normalize(glm::cross(b - a, c - a));
}

const Mesh& meshNamed(const Scene& s, const std::string& n) {
  for (const Mesh& m : s.meshes)
    if (m.name == n) return m;
  throw std::runtime_error("no mesh " + n);
}

std::vector<const Mesh*> lights(const Scene& s) {
  std::vector<const Mesh*> out;
  for (const Mesh& m : s.meshes)
    if (s.materials[m.material].flags & kMaterialLight) out.push_back(&m);
  return out;
}

}  // namespace

TEST(RtScenes, TriangleBackplane) {
  Scene s = loadScene(kRt / "triangle_backplane.obj");
  const Mesh& back = meshNamed(s, "backplane");
  EXPECT_EQ(back.bounds.min.z, -0.8f);
  EXPECT_EQ(back.bounds.max.z, -0.8f);
  EXPECT_GT(firstFaceNormal(back).z, 0.99f);  // faces the viewer looking down -z
  EXPECT_EQ(meshNamed(s, "triangle").triangleCount(), 1u);
  auto ls = lights(s);
  ASSERT_EQ(ls.size(), 3u);
  for (const Mesh* l : ls) {
    EXPECT_EQ(l->triangleCount(), 2u);  // area lights
    EXPECT_EQ(l->bounds.min.z, 3.0f);
    EXPECT_LT(firstFaceNormal(*l).z, -0.99f);  // shines down onto the scene
    EXPECT_GT(glm::length(s.materials[l->material].ke), 0.5f);
  }
}

TEST(RtScenes, CubeBackplane) {
  Scene s = loadScene(kRt / "cube_backplane.obj");
  EXPECT_EQ(meshNamed(s, "cube").triangleCount(), 12u);
  EXPECT_EQ(meshNamed(s, "cube").positions.size(), 24u);  // flat faces: generated normals per face
  EXPECT_EQ(lights(s).size(), 3u);
}

TEST(RtScenes, CornellBoxHasInwardWallsALightAndAMirror) {
  Scene s = loadScene(kRt / "cornell_box.obj");
  EXPECT_GT(firstFaceNormal(meshNamed(s, "left")).x, 0.99f);
  EXPECT_LT(firstFaceNormal(meshNamed(s, "right")).x, -0.99f);
  EXPECT_GT(firstFaceNormal(meshNamed(s, "floor")).y, 0.99f);
  EXPECT_LT(firstFaceNormal(meshNamed(s, "ceiling")).y, -0.99f);
  auto ls = lights(s);
  ASSERT_EQ(ls.size(), 1u);
  EXPECT_LT(firstFaceNormal(*ls[0]).y, -0.99f);
  EXPECT_EQ(s.materials[meshNamed(s, "mirror_block").material].mirror, 1.0f);
  Bounds b = s.bounds();
  EXPECT_LT(b.max.z, 0.0f);  // in front of a camera at the origin looking down -z
}
