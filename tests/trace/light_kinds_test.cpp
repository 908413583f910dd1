// The tracer lights by spot and directional lights (shaders/shared/lights.h) with shadow rays for each.
#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "trace/procedural.hpp"
#include "trace/tracer.hpp"

namespace rtr::trace {
namespace {

// A 20 × 20 grid plane at z = 0 facing +z (grey, rough, pbr), and optionally a small blocker box at
// `blocker` (empty box: none).
Scene plane(glm::vec3 blockerLo = glm::vec3(0), glm::vec3 blockerHi = glm::vec3(0)) {
  Scene s;
  Material m;
  m.baseColor = glm::vec3(0.7f);
  m.roughness = 0.6f;
  m.kd = glm::vec3(0.7f);
  m.ka = glm::vec3(0.0f);
  const uint32_t mat = addMaterial(s, m);
  const int n = 20;
  Mesh grid;
  grid.material = mat;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      grid.positions.push_back({20.0f * (float(i) / n - 0.5f), 20.0f * (float(j) / n - 0.5f), 0.0f});
      grid.normals.push_back({0, 0, 1});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, d = a + uint32_t(n + 1), e = d + 1;
      grid.indices.insert(grid.indices.end(), {a, b, e, a, e, d});
    }
  addMesh(s, std::move(grid));
  if (blockerHi != blockerLo) addMesh(s, box(blockerLo, blockerHi, mat));
  return s;
}

TraceSettings settings(Shading shading, std::vector<Light> lights) {
  TraceSettings ts;
  ts.shading = shading;
  ts.bounces = 0;
  ts.lights = LightRig{std::move(lights), glm::vec3(0.0f), ""};
  return ts;
}

// What the tracer sees looking straight down at plane point (x, y).
glm::vec3 at(const Tracer& t, const TraceSettings& ts, float x, float y) {
  return t.traceAndShade(Ray{{x, y, 5.0f}, {0, 0, -1}}, 0, ts);
}

Light spotLight(glm::vec3 pos, float innerDeg, float outerDeg) {
  Light l;
  l.kind = Light::Kind::Spot;
  l.position = pos;
  l.color = glm::vec3(4.0f);
  l.falloff = true;
  l.direction = {0, 0, -1};
  l.innerConeCos = std::cos(glm::radians(innerDeg));
  l.outerConeCos = std::cos(glm::radians(outerDeg));
  return l;
}

TEST(LightKinds, SpotLightsInsideItsConeOnly) {
  const Scene s = plane();
  const Tracer t(s);
  const glm::vec3 pos(0, 0, 2);
  Light point = spotLight(pos, 20, 30);
  point.kind = Light::Kind::Point;
  for (Shading shading : {Shading::Phong, Shading::Pbr}) {
    const TraceSettings spot = settings(shading, {spotLight(pos, 20, 30)}), full = settings(shading, {point});
    for (float deg : {0.0f, 10.0f, 19.5f}) {
      const float x = 2.0f * std::tan(glm::radians(deg));
      EXPECT_EQ(at(t, spot, x, 0), at(t, full, x, 0)) << deg;  // inside the inner cone: the point light
      EXPECT_GT(at(t, spot, x, 0).x, 0.01f);
    }
    const float mid = at(t, spot, 2.0f * std::tan(glm::radians(25.0f)), 0).x;
    EXPECT_GT(mid, 0.0f);
    EXPECT_LT(mid, at(t, full, 2.0f * std::tan(glm::radians(25.0f)), 0).x);
    for (float deg : {30.5f, 45.0f, 70.0f}) EXPECT_EQ(at(t, spot, 2.0f * std::tan(glm::radians(deg)), 0), glm::vec3(0)) << deg;
  }
}

TEST(LightKinds, SpotCastsShadows) {
  const Scene s = plane({-0.2f, -0.2f, 1.0f}, {0.2f, 0.2f, 1.2f});  // a tile between the spot and the plane
  const Tracer t(s);
  TraceSettings ts = settings(Shading::Pbr, {spotLight({0, 0, 2}, 20, 30)});
  EXPECT_EQ(at(t, ts, 0.05f, 0.3f), glm::vec3(0));  // under the tile (seen past its side)
  EXPECT_GT(at(t, ts, 0.6f, 0.0f).x, 0.01f);        // beside its shadow
  ts.shadows = false;
  EXPECT_GT(at(t, ts, 0.05f, 0.3f).x, 0.01f);
}

TEST(LightKinds, DirectionalIrradianceIsUniformAndItsShadowsReachFar) {
  Light sun;
  sun.kind = Light::Kind::Directional;
  sun.direction = glm::normalize(glm::vec3(0.3f, 0.0f, -1.0f));
  sun.color = glm::vec3(1.5f);
  sun.position = glm::vec3(0.0f, 0.0f, 0.5f);  // ignored: not a point
  sun.falloff = true;                          // ignored: the sun has no falloff
  sun.range = 0.1f;                            // ignored too
  // A blocker 40 units up the light's way from (-4, -4): the shadow ray must go that far.
  const glm::vec3 c = glm::vec3(-4, -4, 0) - 40.0f * sun.direction;
  const Scene s = plane(c - glm::vec3(0.5f), c + glm::vec3(0.5f));
  const Tracer t(s);
  for (Shading shading : {Shading::Phong, Shading::Pbr}) {
    TraceSettings ts = settings(shading, {sun});
    ts.width = 64;
    ts.height = 64;
    ts.lens.orthographic = true;
    ts.lens.orthoHalfHeight = 9.0f;
    ts.pose = CameraPose{{0, 0, 10}, 0, 0};  // looking down -z at the plane; parallel rays: one view direction
    ImageF img;
    t.render(ts, img);  // primary and shadow rays in packets
    const glm::vec3 lit(img.at(ts.width - 1, ts.height - 1));
    EXPECT_GT(lit.x, 0.1f);
    EXPECT_GT(at(t, ts, 5.0f, 5.0f).x, 0.1f);
    int shadowed = 0, same = 0;
    for (uint32_t y = 0; y < ts.height; ++y)
      for (uint32_t x = 0; x < ts.width; ++x) {
        const glm::vec3 p(img.at(x, y));
        ASSERT_EQ(p, t.traceAndShade(t.calculateRay(ts, x, y), 0, ts)) << x << "," << y;  // packets = single rays
        if (p == glm::vec3(0)) ++shadowed;
        else if (std::abs(p.x - lit.x) < 1e-6f * lit.x) ++same;  // the view angle is the same everywhere
      }
    EXPECT_GT(shadowed, 5);
    EXPECT_EQ(shadowed + same, int(ts.width * ts.height)) << int(shading);
    EXPECT_EQ(at(t, ts, -4, -4), glm::vec3(0));
  }
}

TEST(LightKinds, RangeCutsThePointLightOff) {
  const Scene s = plane();
  const Tracer t(s);
  Light l;
  l.position = {0, 0, 1};
  l.color = glm::vec3(2.0f);
  l.falloff = true;
  l.range = 3.0f;
  for (Shading shading : {Shading::Phong, Shading::Pbr}) {
    const TraceSettings ts = settings(shading, {l});
    EXPECT_GT(at(t, ts, 1.0f, 0.0f).x, 0.0f);
    EXPECT_GT(at(t, ts, 2.8f, 0.0f).x, 0.0f);                        // distance 2.97
    EXPECT_EQ(at(t, ts, 2.9f, 0.0f), glm::vec3(0)) << int(shading);  // distance 3.07
    EXPECT_EQ(at(t, ts, 6.0f, 3.0f), glm::vec3(0));
  }
}

}  // namespace
}  // namespace rtr::trace
