// The shared light model (shaders/shared/lights.h) compiled as C++: point, spot and directional lights,
// glTF's smooth cone edge and range window, against the definitions of KHR_lights_punctual.
#include "lights.h"

#include <cmath>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

namespace rtr::shader {
namespace {

const vec3 kColor(2.0f, 1.0f, 0.5f);

GpuLight spot(vec3 pos, vec3 dir, float innerDeg, float outerDeg, float range = 0.0f) {
  return makeGpuLight(LIGHT_SPOT, pos, kColor, true, glm::normalize(dir), std::cos(glm::radians(innerDeg)),
                      std::cos(glm::radians(outerDeg)), range);
}

// The point at angle `deg` off the spot's axis (-y from the origin), on the plane y = -2.
vec3 atAngle(float deg) { return {2.0f * std::tan(glm::radians(deg)), -2.0f, 0.0f}; }

TEST(Lights, SpotIsFullInsideTheInnerConeAndDarkOutsideTheOuter) {
  const GpuLight s = spot(vec3(0), vec3(0, -1, 0), 20.0f, 30.0f);
  for (float deg : {0.0f, 10.0f, 19.9f}) {
    const vec3 p = atAngle(deg);
    const LightSample ls = lightSample(s, p);
    const float d2 = glm::dot(p, p);
    EXPECT_FLOAT_EQ(ls.radiance.x, kColor.x / d2) << deg;  // a point light with inverse-square falloff
    EXPECT_NEAR(ls.distance, std::sqrt(d2), 1e-5f);
    EXPECT_NEAR(glm::dot(ls.l, glm::normalize(-p)), 1.0f, 1e-6f);
  }
  for (float deg : {30.1f, 45.0f, 89.0f}) EXPECT_EQ(lightSample(s, atAngle(deg)).radiance, vec3(0)) << deg;
  // Behind the light.
  EXPECT_EQ(lightSample(s, vec3(0, 1, 0)).radiance, vec3(0));
}

TEST(Lights, SpotEdgeIsTheSquaredRampInTheCosine) {
  const float inner = std::cos(glm::radians(20.0f)), outer = std::cos(glm::radians(30.0f));
  const GpuLight s = spot(vec3(0), vec3(0, -1, 0), 20.0f, 30.0f);
  float prev = 2.0f;
  for (float deg = 20.5f; deg < 30.0f; deg += 0.5f) {
    const vec3 p = atAngle(deg);
    const float t = (std::cos(glm::radians(deg)) - outer) / (inner - outer);
    const float got = lightSample(s, p).radiance.x * glm::dot(p, p) / kColor.x;
    EXPECT_NEAR(got, t * t, 1e-4f) << deg;
    EXPECT_LT(got, prev) << deg;  // falls monotonically towards the outer edge
    prev = got;
  }
  // Continuous at both edges.
  const auto factor = [&](float deg) {
    return lightSample(s, atAngle(deg)).radiance.x * glm::dot(atAngle(deg), atAngle(deg)) / kColor.x;
  };
  EXPECT_NEAR(factor(19.999f), factor(20.001f), 3e-4f);
  EXPECT_NEAR(factor(29.999f), 0.0f, 1e-6f);
  // A spot pointing elsewhere turns the same way: the cone follows `direction`.
  const GpuLight tilted = spot(vec3(1, 2, 3), vec3(1, 0, 0), 10.0f, 15.0f);
  EXPECT_GT(lightSample(tilted, vec3(6, 2, 3)).radiance.x, 0.0f);
  EXPECT_EQ(lightSample(tilted, vec3(1, 2, -2)).radiance, vec3(0));
}

TEST(Lights, DirectionalGivesTheSameRadianceEverywhere) {
  const vec3 dir = glm::normalize(vec3(1, -2, 0.5f));
  const GpuLight d = makeGpuLight(LIGHT_DIRECTIONAL, vec3(0), kColor, true, dir, 1.0f, 0.0f, 5.0f);
  for (vec3 p : {vec3(0), vec3(1e4f, -3, 7), vec3(-0.001f, 1e3f, -1e5f)}) {
    const LightSample ls = lightSample(d, p);
    EXPECT_EQ(ls.radiance, kColor);  // no falloff, no range, whatever the flags say
    EXPECT_EQ(ls.l, -dir);
    EXPECT_EQ(ls.distance, LIGHT_FAR);
  }
}

TEST(Lights, RangeWindowEndsTheLightAtItsRange) {
  const float range = 3.0f;
  for (unsigned kind : {unsigned(LIGHT_POINT), unsigned(LIGHT_SPOT)}) {
    const GpuLight l = makeGpuLight(kind, vec3(0), kColor, false, vec3(0, -1, 0), 0.9f, 0.5f, range);
    for (float d : {0.5f, 1.5f, 2.9f}) {
      const float x = d / range;
      EXPECT_NEAR(lightSample(l, vec3(0, -d, 0)).radiance.x, kColor.x * (1.0f - x * x * x * x), 1e-5f) << d;
    }
    for (float d : {3.0f, 3.01f, 100.0f}) EXPECT_EQ(lightSample(l, vec3(0, -d, 0)).radiance, vec3(0)) << d;
  }
  // No range: unbounded.
  const GpuLight far = makeGpuLight(LIGHT_POINT, vec3(0), kColor, false, vec3(0), 1.0f, 0.0f, 0.0f);
  EXPECT_EQ(lightSample(far, vec3(0, -1e4f, 0)).radiance, kColor);
}

TEST(Lights, PointLightFormKeepsItsMeaning) {
  const vec3 pos(1, 2, 3), p(-1, 0.5f, 2);
  for (bool falloff : {false, true}) {
    const LightSample a = lightSample(pos, kColor, falloff, p);
    const LightSample b = lightSample(makeGpuLight(LIGHT_POINT, pos, kColor, falloff, vec3(0), 1, 0, 0), p);
    EXPECT_EQ(a.l, b.l);
    EXPECT_EQ(a.radiance, b.radiance);
    EXPECT_FLOAT_EQ(a.radiance.x, falloff ? kColor.x / glm::dot(pos - p, pos - p) : kColor.x);
  }
}

}  // namespace
}  // namespace rtr::shader
