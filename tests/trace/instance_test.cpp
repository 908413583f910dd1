// Instances in the tracer (Scene::instances, the two-level InstanceBvh): the same image, hit distances and
// normals as the scene flattened into one copy per placement, and each mesh stored once.
#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/matrix.hpp>

#include "core/error.hpp"
#include "trace/procedural.hpp"
#include "trace/tracer.hpp"

namespace rtr::trace {
namespace {

Material pbrMaterial(glm::vec3 c, float rough, float metal) {
  Material m;
  m.baseColor = c;
  m.roughness = rough;
  m.metalness = metal;
  return m;
}

// Meshes: 0 a sphere, 1 a box, 2 a floor quad, 3 a box no instance places (right in front of the camera).
// Placements: rotated, non-uniformly scaled, mirrored (negative determinant) and plain.
Scene instancedScene() {
  Scene s;
  const uint32_t red = addMaterial(s, pbrMaterial({0.8f, 0.2f, 0.1f}, 0.4f, 0.0f));
  const uint32_t metal = addMaterial(s, pbrMaterial({0.9f, 0.8f, 0.5f}, 0.3f, 1.0f));
  const uint32_t grey = addMaterial(s, pbrMaterial({0.6f, 0.6f, 0.6f}, 0.8f, 0.0f));
  addMesh(s, uvSphere({0.2f, 0.1f, 0.0f}, 0.7f, 12, 20, red));
  addMesh(s, box({-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}, metal));
  addMesh(s, quad({-6, -1, 6}, {12, 0, 0}, {0, 0, -12}, grey));
  addMesh(s, box({-0.2f, -0.2f, 6.5f}, {0.2f, 0.2f, 7.0f}, red));
  const glm::mat4 I(1.0f);
  s.instances = {
      {0, glm::translate(I, {-2.0f, 0.0f, 0.0f})},
      {0, glm::scale(glm::rotate(glm::translate(I, {0.0f, 0.3f, -1.0f}), 0.7f, glm::vec3(0.3f, 1.0f, 0.2f)), {1.3f, 0.6f, 0.9f})},
      {0, glm::scale(glm::translate(I, {2.2f, 0.0f, 0.5f}), {-1.0f, 1.0f, 1.0f})},  // mirrored
      {1, glm::rotate(glm::translate(I, {1.0f, -0.4f, 2.0f}), 0.5f, glm::vec3(0.0f, 1.0f, 0.0f))},
      {1, glm::scale(glm::translate(I, {-1.5f, 1.2f, 1.5f}), {0.5f, -0.7f, 0.5f})},  // mirrored
      {2, I},
  };
  return s;
}

// One copy of each placed mesh: vertices transformed, normals by the inverse transpose, the winding
// flipped where the transform mirrors.
Scene flattened(const Scene& in) {
  Scene s;
  s.materials = in.materials;
  for (const Instance& inst : in.instances) {
    Mesh m = in.meshes[inst.mesh];
    const glm::mat3 nm = glm::transpose(glm::inverse(glm::mat3(inst.transform)));
    for (glm::vec3& p : m.positions.writable()) p = glm::vec3(inst.transform * glm::vec4(p, 1.0f));
    for (glm::vec3& n : m.normals.writable()) n = nm * n;  // not normalised: then interpolation and transform commute
    if (glm::determinant(glm::mat3(inst.transform)) < 0.0f)
      for (size_t i = 0; i < m.indices.size(); i += 3) std::swap(m.indices.writable()[i + 1], m.indices.writable()[i + 2]);
    addMesh(s, std::move(m));
  }
  return s;
}

TraceSettings settings() {
  TraceSettings ts;
  ts.width = 96;
  ts.height = 72;
  ts.shading = Shading::Pbr;
  ts.pose = CameraPose{{0.0f, 1.5f, 8.0f}, 0.0f, -10.0f};
  Light l;
  l.position = {2.0f, 5.0f, 4.0f};
  l.color = glm::vec3(1.5f);
  ts.lights = LightRig{{l}, glm::vec3(0.05f), ""};
  return ts;
}

TEST(Instances, TraceTheSameImageAsTheFlattenedCopy) {
  const Scene inst = instancedScene(), flat = flattened(inst);
  const Tracer ti(inst), tf(flat);
  EXPECT_TRUE(ti.instanced());
  // Each placed mesh stored once; the unplaced one not at all.
  EXPECT_EQ(ti.triangles().size(),
            size_t(inst.meshes[0].triangleCount() + inst.meshes[1].triangleCount() + inst.meshes[2].triangleCount()));
  EXPECT_GT(tf.triangles().size(), ti.triangles().size());
  for (const bool shadows : {true, false}) {
    TraceSettings ts = settings();
    ts.shadows = shadows;
    ImageF a, b;
    ti.render(ts, a);
    tf.render(ts, b);
    int differ = 0, lit = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i) {
      const glm::vec4 d = glm::abs(a.pixels[i] - b.pixels[i]);
      if (std::max({d.x, d.y, d.z}) > 2e-3f) ++differ;
      if (b.pixels[i].x > 0.1f) ++lit;
    }
    // Float rounding differs (object-space rays against scene-space triangles): at most a few edge pixels.
    EXPECT_LE(differ, int(a.pixels.size() / 500)) << "shadows " << shadows;
    EXPECT_GT(lit, int(a.pixels.size() / 4));
    // Rendered = traced one pixel at a time.
    for (uint32_t y = 0; y < ts.height; y += 7)
      for (uint32_t x = 0; x < ts.width; x += 5)
        ASSERT_EQ(glm::vec3(a.at(x, y)), ti.traceAndShade(ti.calculateRay(ts, x, y), ts.bounces, ts));
  }
}

TEST(Instances, HitDistancesAndNormalsAreInSceneSpace) {
  const Scene inst = instancedScene(), flat = flattened(inst);
  const Tracer ti(inst), tf(flat);
  const TraceSettings ts = settings();
  int both = 0, mismatch = 0;
  std::vector<int> seen(inst.instances.size(), 0);
  for (uint32_t y = 0; y < ts.height; y += 2)
    for (uint32_t x = 0; x < ts.width; x += 2) {
      const Ray r = ti.calculateRay(ts, x, y);
      const Hit hi = ti.closestTriangle(r), hf = tf.closestTriangle(r);
      if (hi.hit() != hf.hit()) {
        ++mismatch;
        continue;
      }
      if (!hi.hit()) continue;
      ++both;
      ++seen[hi.instance];
      EXPECT_NEAR(hi.t, hf.t, 1e-5f * hf.t);
      const SurfacePoint si = ti.surface(r, hi), sf = tf.surface(r, hf);
      EXPECT_LT(glm::distance(si.position, sf.position), 1e-4f);
      EXPECT_GT(glm::dot(si.geomNormal, sf.geomNormal), 0.99999f);
      EXPECT_GT(glm::dot(si.normal, sf.normal), 0.99999f);
      EXPECT_NEAR(glm::length(si.normal), 1.0f, 1e-5f);
      EXPECT_EQ(si.mesh, inst.instances[hi.instance].mesh);
      // Shadow rays agree too.
      const Ray toLight = Ray{si.position + 1e-3f * si.geomNormal, glm::vec3(2, 5, 4) - si.position, 1.0f};
      EXPECT_EQ(ti.occluded(toLight), tf.occluded(toLight));
    }
  EXPECT_LE(mismatch, 3);
  EXPECT_GT(both, 500);
  for (size_t i = 0; i < seen.size(); ++i) EXPECT_GT(seen[i], 0) << "instance " << i << " never seen";
}

TEST(Instances, BadPlacementsAreErrors) {
  Scene s = instancedScene();
  s.instances.push_back({7, glm::mat4(1.0f)});
  EXPECT_THROW(Tracer{s}, Error);
  s.instances.back() = {0, glm::mat4(0.0f)};
  EXPECT_THROW(Tracer{s}, Error);
}

}  // namespace
}  // namespace rtr::trace
