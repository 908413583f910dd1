// The tracer's glTF materials: the BRDF each material gets (shaders/shared/brdf.h) and its overrides.
#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "brdf.h"
#include "lights.h"
#include "trace/procedural.hpp"
#include "trace/tracer.hpp"

namespace rtr::trace {
namespace {

// Two quads side by side facing +z, x < 0 with an OBJ-like material, x > 0 with a glTF one, same factors.
Scene twoMaterials() {
  Scene s;
  Material m;
  m.baseColor = glm::vec3(0.8f, 0.6f, 0.4f);
  m.roughness = 0.35f;
  m.metalness = 0.4f;
  const uint32_t obj = addMaterial(s, m);
  m.flags = kMaterialGltf;
  const uint32_t gltf = addMaterial(s, m);
  addMesh(s, quad({-2, -1, 0}, {2, 0, 0}, {0, 2, 0}, obj));
  addMesh(s, quad({0, -1, 0}, {2, 0, 0}, {0, 2, 0}, gltf));
  return s;
}

TEST(GltfMaterial, GltfUsesGgxAndTheRestBeckmannUnlessOverridden) {
  const Scene s = twoMaterials();
  const Tracer t(s);
  TraceSettings ts;
  ts.shading = Shading::Pbr;
  ts.bounces = 0;
  Light l;
  l.position = {0.3f, 0.5f, 2.0f};
  ts.lights = LightRig{{l}, glm::vec3(0.0f), ""};
  const Ray left{{-0.5f, 0.2f, 3.0f}, glm::normalize(glm::vec3(-0.2f, -0.1f, -1.0f))};   // hits x = -1.1
  const Ray right{{1.5f, 0.2f, 3.0f}, glm::normalize(glm::vec3(-0.2f, -0.1f, -1.0f))};   // hits x = 0.9
  const glm::vec3 objDefault = t.traceAndShade(left, 0, ts), gltfDefault = t.traceAndShade(right, 0, ts);
  ts.brdf = Brdf::Ggx;
  const glm::vec3 objGgx = t.traceAndShade(left, 0, ts);
  EXPECT_EQ(t.traceAndShade(right, 0, ts), gltfDefault);
  ts.brdf = Brdf::Beckmann;
  EXPECT_EQ(t.traceAndShade(left, 0, ts), objDefault);
  const glm::vec3 gltfBeckmann = t.traceAndShade(right, 0, ts);
  // Each is the shared header's BRDF of that name at that point.
  const glm::vec3 v = -glm::normalize(left.direction);
  const SurfacePoint sp = t.surface(left, t.closestTriangle(left));
  const shader::LightSample ls = shader::lightSample(l.position, l.color, false, sp.position);
  const auto direct = [&](int brdf) {
    return shader::pbrDirect(brdf, sp.normal, v, ls.l, ls.radiance, glm::vec3(0.8f, 0.6f, 0.4f), 0.35f, 0.4f);
  };
  EXPECT_EQ(objDefault, direct(BRDF_BECKMANN));
  EXPECT_EQ(objGgx, direct(BRDF_GGX));
  EXPECT_NE(objDefault, objGgx);
  EXPECT_NE(gltfDefault, gltfBeckmann);
}

}  // namespace
}  // namespace rtr::trace
