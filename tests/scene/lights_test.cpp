// Which lights light a scene (scene/lights.hpp), how .rtrscene stores them, and how a scene is framed.
#include "scene/lights.hpp"

#include <cstring>

#include <gtest/gtest.h>

#include "core/error.hpp"
#include "scene/rtrscene.hpp"

namespace rtr {
namespace {

// A unit quad (two triangles) at height y with material `mat`.
Mesh quad(float y, uint32_t mat) {
  Mesh m;
  m.material = mat;
  m.positions = {{-1, y, -1}, {1, y, -1}, {1, y, 1}, {-1, y, 1}};
  m.normals.assign(4, {0, -1, 0});
  m.indices = {0, 1, 2, 0, 2, 3};
  for (const glm::vec3& p : m.positions) m.bounds.extend(p);
  return m;
}

Scene bareScene() {
  Scene s;
  Material m;
  m.name = "grey";
  s.materials.push_back(m);
  s.meshes.push_back(quad(0.0f, 0));
  return s;
}

Scene litScene() {  // the course's way: a "light" material with Ke on a quad
  Scene s = bareScene();
  Material light;
  light.name = "ceiling_light";
  light.ke = {2, 1.5f, 1};
  s.materials.push_back(light);
  s.meshes.push_back(quad(3.0f, 1));
  return s;
}

TEST(Lights, GeometryLightsWhenNothingElse) {
  const LightRig rig = resolveLights(litScene());
  ASSERT_EQ(rig.lights.size(), 1u);
  EXPECT_EQ(rig.lights[0].kind, Light::Kind::Area);
  EXPECT_EQ(rig.lights[0].position, glm::vec3(0, 3, 0));
  EXPECT_EQ(rig.lights[0].color, glm::vec3(2, 1.5f, 1));
  EXPECT_FALSE(rig.lights[0].falloff);
  EXPECT_TRUE(rig.note.empty()) << rig.note;
  EXPECT_TRUE(hasOwnLights(litScene()));
}

TEST(Lights, StoredLightsWinOverGeometryAndCommandLineWinsOverBoth) {
  Scene s = litScene();
  Light stored;
  stored.position = {5, 6, 7};
  stored.color = glm::vec3(0.5f);
  s.lights = {stored};
  LightRig rig = resolveLights(s);
  ASSERT_EQ(rig.lights.size(), 1u);
  EXPECT_EQ(rig.lights[0].position, glm::vec3(5, 6, 7));
  LightOptions o;
  o.position = glm::vec3(-1, 2, -3);
  o.color = {1, 0, 0};
  o.falloff = true;
  o.ambient = {0.1f, 0.2f, 0.3f};
  rig = resolveLights(s, o);
  ASSERT_EQ(rig.lights.size(), 1u);
  EXPECT_EQ(rig.lights[0].kind, Light::Kind::Point);
  EXPECT_EQ(rig.lights[0].position, glm::vec3(-1, 2, -3));
  EXPECT_EQ(rig.lights[0].color, glm::vec3(1, 0, 0));
  EXPECT_TRUE(rig.lights[0].falloff);
  EXPECT_EQ(rig.ambient, glm::vec3(0.1f, 0.2f, 0.3f));
  EXPECT_FALSE(rig.note.empty());
}

TEST(Lights, ABareSceneGetsAHeadlightAndSaysSo) {
  const Scene s = bareScene();
  EXPECT_FALSE(hasOwnLights(s));
  LightOptions o;
  o.falloff = true;  // never on the headlight: it would light a model by its distance from the camera
  LightRig rig = resolveLights(s, o);
  ASSERT_EQ(rig.lights.size(), 1u);
  EXPECT_EQ(rig.lights[0].kind, Light::Kind::Headlight);
  EXPECT_FALSE(rig.lights[0].falloff);
  EXPECT_NE(rig.note.find("headlight"), std::string::npos) << rig.note;
  o.defaultLight = false;
  rig = resolveLights(s, o);
  EXPECT_TRUE(rig.lights.empty());
  EXPECT_NE(rig.note.find("no lights"), std::string::npos) << rig.note;
}

TEST(Lights, AtMostMaxLightsAreKept) {
  Scene s = bareScene();
  for (int i = 0; i < 11; ++i) {
    Light l;
    l.position = {float(i), 1, 0};
    s.lights.push_back(l);
  }
  const LightRig rig = resolveLights(s);
  ASSERT_EQ(rig.lights.size(), kMaxLights);
  EXPECT_EQ(rig.lights.back().position.x, float(kMaxLights - 1));
  EXPECT_NE(rig.note.find("11 lights"), std::string::npos) << rig.note;
}

TEST(Lights, RtrSceneStoresLightsAndStillReadsVersion1) {
  Scene s = litScene();
  Light a, b;
  a.position = {1, 2, 3};
  a.color = {4, 5, 6};
  a.falloff = true;
  b = resolveLights(litScene()).lights[0];  // an area light, every field set
  s.lights = {a, b};
  const std::string bytes = encodeRtrScene(s);
  const Scene got = decodeRtrScene({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()}, "mem.rtrscene");
  ASSERT_EQ(got.lights.size(), 2u);
  EXPECT_EQ(got.lights[0].kind, Light::Kind::Point);
  EXPECT_EQ(got.lights[0].position, a.position);
  EXPECT_EQ(got.lights[0].color, a.color);
  EXPECT_TRUE(got.lights[0].falloff);
  EXPECT_EQ(got.lights[1].kind, Light::Kind::Area);
  for (auto f : {&Light::position, &Light::color, &Light::corner, &Light::edge1, &Light::edge2, &Light::normal})
    EXPECT_EQ(got.lights[1].*f, b.*f);

  // A version-1 file: no lights, the light count field reserved (0). The header is outside the checksum.
  s.lights.clear();
  std::string v1 = encodeRtrScene(s, 1);
  const uint32_t one = 1;
  const auto view = [](const std::string& b) {
    return std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(b.data()), b.size());
  };
  EXPECT_TRUE(decodeRtrScene(view(v1), "v1.rtrscene").lights.empty());
  std::memcpy(v1.data() + 28, &one, 4);
  EXPECT_THROW(decodeRtrScene(view(v1), "v1.rtrscene"), Error);
}

TEST(Lights, ALightCountTheFileCannotHoldIsRefused) {
  Scene s = bareScene();
  s.lights = {Light{}};
  const std::string good = encodeRtrScene(s);
  const auto view = [](const std::string& b) {
    return std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(b.data()), b.size());
  };
  // The light count beyond what the file holds, before anything is allocated.
  std::string big = good;
  const uint32_t huge = 0x10000000u;
  std::memcpy(big.data() + 28, &huge, 4);
  EXPECT_THROW(decodeRtrScene(view(big), "big.rtrscene"), Error);
}

}  // namespace
}  // namespace rtr
