// What every tool does with a file before its first picture (issue 28): normals split at a crease, indices
// that point nowhere dropped, vertex colours read, light colours from Kd, black lights replaced, the up
// axis, the staged side, never from below, the course scene rule and the empty-image warning.
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>
#include <glm/trigonometric.hpp>

#include "core/error.hpp"
#include "scene/first_look.hpp"
#include "scene/framing.hpp"
#include "scene/lights.hpp"
#include "scene/load.hpp"

namespace fs = std::filesystem;
using namespace rtr;
using ::testing::HasSubstr;

namespace {

struct FirstLook : ::testing::Test {
  fs::path dir = fs::temp_directory_path() / ("rtr_first_look_" + std::to_string(::getpid()));
  std::vector<std::string> warnings, notes;
  LoadOptions opt;
  void SetUp() override {
    fs::remove_all(dir);
    fs::create_directories(dir);
    opt.warn = [this](const std::string& w) { warnings.push_back(w); };
    opt.note = [this](const std::string& n) { notes.push_back(n); };
  }
  void TearDown() override { fs::remove_all(dir); }
  Scene load(const std::string& obj, const std::string& mtl = "") {
    std::ofstream(dir / "t.obj", std::ios::binary) << obj;
    if (!mtl.empty()) std::ofstream(dir / "t.mtl", std::ios::binary) << mtl;
    return loadScene(dir / "t.obj", opt);
  }
};

// A unit cube as quads, no normals.
const std::string kCube =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";

size_t distinctNormals(const Mesh& m) {
  std::set<std::tuple<float, float, float>> n;
  for (const glm::vec3& v : m.normals) n.insert({v.x, v.y, v.z});
  return n.size();
}

TEST_F(FirstLook, NormalsAreSplitAtTheCreaseAngle) {
  const Scene hard = load(kCube);  // default 40°: every face flat, a corner thrice
  ASSERT_EQ(hard.meshes.size(), 1u);
  EXPECT_EQ(hard.meshes[0].positions.size(), 24u);
  EXPECT_EQ(distinctNormals(hard.meshes[0]), 6u);
  for (const glm::vec3& n : hard.meshes[0].normals)
    EXPECT_NEAR(std::max({std::abs(n.x), std::abs(n.y), std::abs(n.z)}), 1.0f, 1e-6f);
  opt.creaseDeg = 180;  // smooth: one normal per corner, leaning into all three faces
  const Scene smooth = load(kCube);
  EXPECT_EQ(smooth.meshes[0].positions.size(), 8u);
  for (const glm::vec3& n : smooth.meshes[0].normals)
    EXPECT_GT(std::min({std::abs(n.x), std::abs(n.y), std::abs(n.z)}), 0.3f) << n.x << " " << n.y << " " << n.z;
  opt.creaseDeg = 0;  // flat
  EXPECT_EQ(load(kCube).meshes[0].positions.size(), 24u);
  // A gently curved strip (20° between neighbours) stays smooth at 40° and is cut at 10°.
  std::string strip;
  for (int i = 0; i < 4; ++i) {
    const float a = glm::radians(20.0f * float(i));
    strip += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
    strip += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 1\n";
  }
  strip += "f 1 3 4 2\nf 3 5 6 4\nf 5 7 8 6\n";
  opt.creaseDeg = 40;
  EXPECT_EQ(load(strip).meshes[0].positions.size(), 8u);
  opt.creaseDeg = 10;
  EXPECT_EQ(load(strip).meshes[0].positions.size(), 12u);
}

TEST_F(FirstLook, IndicesThatPointNowhereAreDroppedForTheFace) {
  // Normal indices with no `vn` at all (as some exporters write), and a texcoord index past the end.
  const Scene s = load(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\n"
      "f 1//1 2//1 3//1\nf 1/1/1 3/5/1 4/1/1\n");
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].triangleCount(), 2u);
  for (const glm::vec3& n : s.meshes[0].normals) EXPECT_NEAR(n.z, 1.0f, 1e-6f);  // computed
  ASSERT_EQ(warnings.size(), 1u) << "one warning for all such faces";
  EXPECT_THAT(warnings[0], HasSubstr("t.obj:6: face normal index 1 points nowhere"));
  // One corner's normal points nowhere: the whole face's normals are computed, not a mix.
  const Scene mixed = load("v 0 0 0\nv 1 0 0\nv 1 1 0\nvn 1 0 0\nf 1//1 2//1 3//7\n");
  for (const glm::vec3& n : mixed.meshes[0].normals) EXPECT_NEAR(n.z, 1.0f, 1e-6f);
}

TEST_F(FirstLook, VertexColoursAreRead) {
  const Scene s = load("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nv 0 0 1\nf 1 2 3\nf 1 2 4\n");
  const Mesh& m = s.meshes[0];
  ASSERT_EQ(m.colors.size(), m.positions.size());
  for (size_t i = 0; i < m.positions.size(); ++i) {
    const glm::vec3 p = m.positions[i];
    const glm::vec4 want = p == glm::vec3(0, 0, 0)   ? glm::vec4(1, 0, 0, 1)
                           : p == glm::vec3(1, 0, 0) ? glm::vec4(0, 1, 0, 1)
                           : p == glm::vec3(0, 1, 0) ? glm::vec4(0, 0, 1, 1)
                                                     : glm::vec4(1);  // no colour: white
    EXPECT_EQ(m.colors[i], want) << i;
  }
  EXPECT_TRUE(load("v 0 0 0 1\nv 1 0 0 1\nv 0 1 0 1\nf 1 2 3\n").meshes[0].colors.empty()) << "a 4th number is w";
}

TEST_F(FirstLook, ALightWithoutKeTakesItsColourFromKd) {
  const Scene s = load("mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl light\nf 1 2 3\n", "newmtl light\nKd 0.8 0.6 0.4\n");
  const LightRig rig = resolveLights(s);
  ASSERT_EQ(rig.lights.size(), 1u);
  EXPECT_EQ(rig.lights[0].color, glm::vec3(0.8f, 0.6f, 0.4f));
}

TEST_F(FirstLook, BlackLightsGiveWayToTheHeadlight) {
  const Scene s = load("mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl light\nf 1 2 3\n", "newmtl light\nKd 0 0 0\n");
  LightRig rig = resolveLights(s);
  ASSERT_EQ(rig.lights.size(), 1u);
  EXPECT_EQ(rig.lights[0].kind, Light::Kind::Headlight);
  EXPECT_THAT(rig.note, HasSubstr("all black"));
  LightOptions strict;
  strict.defaultLight = false;
  EXPECT_EQ(resolveLights(s, strict).lights[0].kind, Light::Kind::Point) << "--no-default-light keeps them";
}

// A Cornell box of our own: floor, ceiling, back wall at +z and two side walls, open at -z (the front),
// walls facing inwards, a ceiling light without Ke.
const std::string kBox =
    "mtllib t.mtl\n"
    "v 0 0 0\nv 10 0 0\nv 10 0 10\nv 0 0 10\nv 0 10 0\nv 10 10 0\nv 10 10 10\nv 0 10 10\n"
    "v 4 9.9 4\nv 6 9.9 4\nv 6 9.9 6\nv 4 9.9 6\n"
    "usemtl white\nf 1 4 3 2\nf 5 6 7 8\nf 4 8 7 3\n"
    "usemtl red\nf 1 5 8 4\nusemtl green\nf 2 3 7 6\n"
    "usemtl light\nf 9 10 11 12\n";
const std::string kBoxMtl =
    "newmtl white\nKd 0.7 0.7 0.7\nnewmtl red\nKd 0.7 0.1 0.1\nnewmtl green\nKd 0.1 0.7 0.1\n"
    "newmtl light\nKd 1 1 1\n";

TEST_F(FirstLook, AStagedBoxIsSeenFromItsOpenSide) {
  Scene s = load(kBox, kBoxMtl);
  EXPECT_TRUE(isCourseScene(s));
  const CameraPose p = framingPose(s, Lens{}, 1.0f);
  EXPECT_EQ(p.yawDeg, 180.0f) << "looking +z into the box";
  EXPECT_EQ(p.pitchDeg, 0.0f);
  EXPECT_LT(p.position.z, 0.0f);
  EXPECT_NEAR(p.position.x, 5.0f, 1e-4f);
  // The same box turned to open towards +x is seen from +x.
  turnScene(s, glm::mat3(glm::vec3(0, 0, 1), glm::vec3(0, 1, 0), glm::vec3(-1, 0, 0)));  // -z goes to +x
  const CameraPose q = framingPose(s, Lens{}, 1.0f);
  EXPECT_EQ(q.yawDeg, 90.0f);
  EXPECT_GT(q.position.x, s.bounds().max.x);
}

TEST_F(FirstLook, ACourseSceneIsStillSeenDownMinusZ) {
  // A back plane at z = -1 and a light quad in front of it at z = 2: the course's triangle_backplane layout.
  const Scene s = load(
      "mtllib t.mtl\nv -2 -2 -1\nv 2 -2 -1\nv 2 2 -1\nv -2 2 -1\nv 0 1 2\nv 1 1 2\nv 1 1.5 2\nv 0 1.5 2\n"
      "usemtl grey\nf 1 2 3 4\nusemtl light1\nf 5 6 7 8\n",
      "newmtl grey\nKd 0.5 0.5 0.5\nnewmtl light1\nKe 1 1 1\n");
  const CameraPose p = framingPose(s, Lens{}, 1.0f);
  EXPECT_EQ(p.yawDeg, 0.0f);
  EXPECT_EQ(p.pitchDeg, 0.0f);
  EXPECT_EQ(p.position.x, frameBounds(s.bounds(), Lens{}, 1.0f).position.x);
}

TEST(FirstLookUp, EachAxisTurnsToPlusY) {
  const std::pair<const char*, glm::vec3> axes[] = {{"+X", {1, 0, 0}},  {"-X", {-1, 0, 0}}, {"+Y", {0, 1, 0}},
                                                    {"-Y", {0, -1, 0}}, {"+Z", {0, 0, 1}},  {"-Z", {0, 0, -1}}};
  for (const auto& [name, axis] : axes) {
    const glm::mat3 r = upRotation(name);
    EXPECT_EQ(r * axis, glm::vec3(0, 1, 0)) << name;
    EXPECT_NEAR(glm::determinant(r), 1.0f, 1e-6f) << name << ": a rotation, not a mirror";
  }
  EXPECT_THROW(upRotation("up"), UsageError);
  // A Z-up scene: its mesh and its light turned, its stored view dropped.
  Scene s;
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 0, 2}};
  m.normals = {{0, -1, 0}, {0, -1, 0}, {0, -1, 0}};
  m.indices = {0, 1, 2};
  LodCluster lc;
  lc.center = {0, 0, 1}, lc.coneAxis = {0, 0, -1}, lc.sphere = {0, 0, 3, 0.5f}, lc.parentSphere = {0, 0, 4, 2.0f};
  m.lod.clusters = std::vector<LodCluster>{lc};
  s.meshes.push_back(m);
  s.lights.push_back(Light{});
  s.lights[0].position = {0, 0, 5};
  s.defaultView = CameraPose{};
  turnScene(s, upRotation("+Z"));
  EXPECT_EQ(s.meshes[0].positions[2], glm::vec3(0, 2, 0));
  EXPECT_EQ(s.meshes[0].normals[0], glm::vec3(0, 0, 1));
  EXPECT_EQ(s.meshes[0].bounds.max.y, 2.0f);
  const LodCluster& turned = s.meshes[0].lod.clusters[0];  // the hierarchy turned with its triangles
  EXPECT_EQ(turned.center, glm::vec3(0, 1, 0));
  EXPECT_EQ(turned.coneAxis, glm::vec3(0, -1, 0));
  EXPECT_EQ(turned.sphere, glm::vec4(0, 3, 0, 0.5f));
  EXPECT_EQ(turned.parentSphere, glm::vec4(0, 4, 0, 2.0f));
  EXPECT_EQ(s.lights[0].position, glm::vec3(0, 5, 0));
  EXPECT_FALSE(s.defaultView);
}

TEST_F(FirstLook, ModelsAreDrawnFromBothSidesCourseScenesAsAuthored) {
  Scene model = load(kCube);
  EXPECT_FALSE(isCourseScene(model));
  EXPECT_TRUE(drawBothSides(model));
  EXPECT_TRUE(model.materials[0].flags & kMaterialDoubleSided);
  Scene box = load(kBox, kBoxMtl);
  EXPECT_FALSE(drawBothSides(box));
  Scene foliage = load("mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl leaf.DoubleSided\nf 1 2 3\nusemtl wall\nf 1 3 2\n",
                       "newmtl leaf.DoubleSided\nnewmtl wall\n");
  EXPECT_FALSE(drawBothSides(foliage)) << "a file that says which materials are two-sided keeps the others one-sided";
}

TEST_F(FirstLook, AnEmptyImageIsNamed) {
  const Scene s = load(kCube);
  const CameraPose front{{0.5f, 0.5f, 5.0f}, 0.0f, 0.0f}, away{{0.5f, 0.5f, 5.0f}, 180.0f, 0.0f};
  EXPECT_EQ(emptyImageWarning(s, front, Lens{}, 1.0f, true, 1), "");
  EXPECT_THAT(emptyImageWarning(s, away, Lens{}, 1.0f, false, 1), HasSubstr("outside the view"));
  const CameraPose aside{{50.0f, 0.5f, 5.0f}, 0.0f, 0.0f};
  EXPECT_THAT(emptyImageWarning(s, aside, Lens{}, 1.0f, false, 1), HasSubstr("outside the view"));
  EXPECT_THAT(emptyImageWarning(s, front, Lens{}, 1.0f, false, 0), HasSubstr("--no-default-light"));
  EXPECT_THAT(emptyImageWarning(s, front, Lens{}, 1.0f, false, 1), HasSubstr("no lit pixel"));
}

}  // namespace
