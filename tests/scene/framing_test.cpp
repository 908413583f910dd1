// The pose that frames a scene when none is given (scene/framing.hpp).
#include "scene/framing.hpp"

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

namespace rtr {
namespace {

Mesh triangle(glm::vec3 a, glm::vec3 b, glm::vec3 c, uint32_t material = 0) {
  Mesh m;
  m.material = material;
  m.positions = {a, b, c};
  m.indices = {0, 1, 2};
  for (const glm::vec3& p : m.positions) m.bounds.extend(p);
  return m;
}

// A closed unit cube, faces counter-clockwise seen from outside.
Mesh cube() {
  Mesh m;
  for (int i = 0; i < 8; ++i) m.positions.push_back({float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1)});
  m.indices = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
  for (const glm::vec3& p : m.positions) m.bounds.extend(p);
  return m;
}

Scene sceneOf(Mesh m, std::string material = "grey") {
  Scene s;
  Material mat;
  mat.name = std::move(material);
  s.materials.push_back(mat);
  s.meshes.push_back(std::move(m));
  return s;
}

glm::vec3 toViewer(const CameraPose& p) { return -basis(p).forward; }

TEST(Framing, AClosedModelGetsTheRaisedThreeQuarterView) {
  const Scene s = sceneOf(cube());
  const CameraPose p = framingPose(s, Lens{}, 1.5f);
  EXPECT_EQ(p.yawDeg, 35.0f);
  EXPECT_EQ(p.pitchDeg, -25.0f);
  EXPECT_GT(glm::dot(glm::normalize(s.bounds().center() - p.position), basis(p).forward), 0.9999f);
  EXPECT_GT(frontArea(s, toViewer(p)), 0.0);
}

TEST(Framing, AStagedSceneIsSeenFromTheFront) {
  Scene s = sceneOf(cube(), "ceiling_light");  // a light of its own
  const CameraPose p = framingPose(s, Lens{}, 1.5f);
  const CameraPose front = frameBounds(s.bounds(), Lens{}, 1.5f);
  EXPECT_EQ(p.position, front.position);
  EXPECT_EQ(p.yawDeg, 0.0f);
  EXPECT_EQ(p.pitchDeg, 0.0f);
}

// One-sided sheets are seen from their front: a triangle facing back-left; one facing only down is the one
// model seen from below. A box wound inwards (faces towards its inside) is seen from above.
TEST(Framing, ASheetIsSeenFromItsFrontAndOnlyADownwardSheetFromBelow) {
  const Scene backLeft = sceneOf(triangle({0, 0, 0}, {0, 1, 0}, {1, 0, 1}));  // normal (1, 0, -1)
  ASSERT_EQ(frontArea(backLeft, toViewer(CameraPose{{}, 35.0f, -25.0f})), 0.0) << "the preferred view sees its back";
  CameraPose p = framingPose(backLeft, Lens{}, 1.0f);
  EXPECT_GT(frontArea(backLeft, toViewer(p)), 0.0) << p.yawDeg << " " << p.pitchDeg;
  const Scene down = sceneOf(triangle({0, 0, 0}, {1, 0, 0}, {0, 0, 1}));  // normal -y: its front only from below
  p = framingPose(down, Lens{}, 1.0f);
  EXPECT_EQ(p.pitchDeg, 25.0f);
  // Facing down and sideways: seen better from below, but a view from above sees its front too.
  const Scene slanted = sceneOf(triangle({0, 0, 0}, {1, 1, 0}, {0, 0, 1}));  // normal (1, -1, 0)
  ASSERT_GT(glm::dot(glm::cross(glm::vec3(1, 1, 0), glm::vec3(0, 0, 1)), glm::vec3(1, -1, 0)), 0.0f);
  p = framingPose(slanted, Lens{}, 1.0f);
  EXPECT_EQ(p.pitchDeg, -25.0f) << "never from below while a view from above sees its front";
  EXPECT_GT(frontArea(slanted, toViewer(p)), 0.0);
  Mesh inward = cube();
  for (size_t i = 0; i < inward.indices.size(); i += 3)
    std::swap(inward.indices.writable()[i + 1], inward.indices.writable()[i + 2]);
  const Scene box = sceneOf(inward);
  p = framingPose(box, Lens{}, 1.0f);
  EXPECT_EQ(p.pitchDeg, -25.0f) << "from above, its floor's inside in view, not from below (yaw " << p.yawDeg << ")";
}

TEST(Framing, TwoSidedFacesCountFromBothSides) {
  const Mesh t = triangle({0, 0, 0}, {1, 0, 0}, {0, 0, 1});
  EXPECT_EQ(frontArea(sceneOf(t), {0, 1, 0}), 0.0);
  EXPECT_NEAR(frontArea(sceneOf(t), {0, -1, 0}), 0.5, 1e-6);
  Scene two = sceneOf(t, "leaves.DoubleSided");
  two.materials[0].flags = kMaterialDoubleSided;
  EXPECT_NEAR(frontArea(two, {0, 1, 0}), 0.5, 1e-6);
  EXPECT_NEAR(frontArea(two, {0, -1, 0}), 0.5, 1e-6);
}

// The pass runs in pieces on all cores: every triangle of every mesh counts once, whatever the piece
// boundaries (two meshes of 200 003 and 70 001 triangles; pieces are 65 536 triangles).
TEST(Framing, FrontAreasCountEveryTriangleOnce) {
  Scene s;
  s.materials.resize(1);
  uint32_t seed = 12345;
  auto rnd = [&] { return float((seed = seed * 1664525u + 1013904223u) >> 8) / float(1 << 24); };
  for (size_t triangles : {200003u, 70001u}) {
    Mesh m;
    for (size_t i = 0; i < triangles * 3; ++i) m.positions.push_back({rnd(), rnd(), rnd()}), m.indices.push_back(uint32_t(i));
    s.meshes.push_back(std::move(m));
  }
  const std::vector<glm::vec3> dirs = {{0, 1, 0}, glm::normalize(glm::vec3(1, -2, 3))};
  const std::vector<double> got = frontAreas(s, dirs);
  for (size_t k = 0; k < dirs.size(); ++k) {
    double want = 0;
    for (const Mesh& m : s.meshes)
      for (size_t i = 0; i < m.indices.size(); i += 3) {
        const glm::vec3 n = glm::cross(m.positions[i + 1] - m.positions[i], m.positions[i + 2] - m.positions[i]);
        want += std::max(glm::dot(n, dirs[k]), 0.0f);
      }
    EXPECT_NEAR(got[k], 0.5 * want, 1e-9 * want) << "direction " << k;
  }
}

}  // namespace
}  // namespace rtr
