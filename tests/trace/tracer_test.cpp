// The tracer on scenes built in code: lights, shadows (no acne at any scale), mirrors, tiles, cameras.
#include "trace/tracer.hpp"

#include <cmath>
#include <random>
#include <set>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "scene/load.hpp"
#include "trace/procedural.hpp"
#include "core/error.hpp"
#include "trace/spawn.hpp"
#include "test_paths.hpp"

namespace rtr::trace {
namespace {

Material phong(glm::vec3 kd, float mirror = 0.0f, std::string name = "mat") {
  Material m;
  m.name = std::move(name);
  m.ka = glm::vec3(0.05f);
  m.kd = kd;
  m.ks = glm::vec3(0.3f);
  m.ns = 20.0f;
  m.mirror = mirror;
  return m;
}

Material lightMaterial(glm::vec3 ke) {
  Material m;
  m.name = "light";
  m.flags = kMaterialLight;
  m.ka = m.kd = m.ks = glm::vec3(0.0f);
  m.ke = ke;
  return m;
}

// A plane of n×n quads centred at `c`, spanning `size`, facing +z, with a small cube light above it.
Scene litPlane(glm::vec3 c, float size, int n) {
  Scene s;
  const uint32_t mat = addMaterial(s, phong(glm::vec3(0.7f)));
  const uint32_t light = addMaterial(s, lightMaterial(glm::vec3(1.0f)));
  // One grid with shared vertices, so that no ray slips through a crack between quads.
  Mesh grid;
  grid.material = mat;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      grid.positions.push_back(c + glm::vec3(size * (float(i) / float(n) - 0.5f), size * (float(j) / float(n) - 0.5f), 0.0f));
      grid.normals.push_back({0, 0, 1});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, d = a + uint32_t(n + 1), e = d + 1;
      grid.indices.insert(grid.indices.end(), {a, b, e, a, e, d});
    }
  addMesh(s, std::move(grid));
  const glm::vec3 lc = c + glm::vec3(0.1f * size, 0.2f * size, 0.7f * size);
  addMesh(s, box(lc - glm::vec3(0.01f * size), lc + glm::vec3(0.01f * size), light));
  return s;
}

TEST(Tracer, LightsComeFromGeometry) {
  Scene s;
  const uint32_t l = addMaterial(s, lightMaterial({1, 0.5f, 0.25f}));
  Material named = phong(glm::vec3(1));
  named.name = "ceiling_light";  // found by name, without the flag
  const uint32_t l2 = addMaterial(s, named);
  addMesh(s, quad({-1, 3, -1}, {2, 0, 0}, {0, 0, 2}, l));  // two triangles: area light
  addMesh(s, box({1, 1, 1}, {2, 3, 4}, l2));               // twelve: point light at the centroid
  const std::vector<Light> lights = resolveLights(s).lights;
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_EQ(lights[0].kind, Light::Kind::Area);
  EXPECT_EQ(lights[0].color, glm::vec3(1, 0.5f, 0.25f));
  EXPECT_NEAR(glm::distance(lights[0].position, glm::vec3(0, 3, 0)), 0.0f, 1e-6f);
  EXPECT_NEAR(std::abs(lights[0].normal.y), 1.0f, 1e-6f);
  EXPECT_NEAR(glm::length(glm::cross(lights[0].edge1, lights[0].edge2)), 4.0f, 1e-5f);
  EXPECT_EQ(lights[1].kind, Light::Kind::Point);
  EXPECT_NEAR(glm::distance(lights[1].position, glm::vec3(1.5f, 2, 2.5f)), 0.0f, 1e-5f);
}

// Falloff divides a light's direct term by the squared distance, in both shading models; ambient stays.
TEST(Tracer, FalloffDividesByTheSquaredDistance) {
  Scene s = litPlane({0, 0, 0}, 4.0f, 4);
  const Tracer t(s);
  for (Shading shading : {Shading::Phong, Shading::Pbr}) {
    TraceSettings ts;
    ts.shading = shading;
    LightRig rig = resolveLights(s);
    ASSERT_EQ(rig.lights.size(), 1u);
    rig.ambient = glm::vec3(0.0f);
    const glm::vec3 lightPos = rig.lights[0].position;
    const Ray down{{lightPos.x, lightPos.y, 0.5f}, {0, 0, -1}};  // the plane point right below the light
    ts.lights = rig;
    const glm::vec3 plain = t.traceAndShade(down, 0, ts);
    rig.lights[0].falloff = true;
    ts.lights = rig;
    const glm::vec3 fell = t.traceAndShade(down, 0, ts);
    const float ambient = shading == Shading::Phong ? s.materials[0].ka.x : 0.0f;  // Ka x Lc, no falloff
    const float d2 = lightPos.z * lightPos.z;
    EXPECT_NEAR(fell.x - ambient, (plain.x - ambient) / d2, 1e-5f) << int(shading);
    EXPECT_GT(plain.x - ambient, 0.1f);
  }
}

// A scene without lights is lit from the camera by default; with the default light off only ambient stays.
TEST(Tracer, HeadlightSitsAtTheCamera) {
  Scene s;
  const uint32_t mat = addMaterial(s, phong(glm::vec3(0.7f)));
  addMesh(s, quad({-1, -1, -3}, {2, 0, 0}, {0, 2, 0}, mat));  // faces +z, towards the camera
  const Tracer t(s);
  TraceSettings ts;
  ts.width = ts.height = 16;
  ts.pose = CameraPose{{0.5f, 0, 2}, 0, 0};
  ts.lights = resolveLights(s);
  ImageF img;
  t.render(ts, img);
  // Lambert + Blinn-Phong with the light at the eye: the brightest pixel is the one that looks along n.
  const glm::vec4 centre = img.pixels[8 * 16 + 8];
  const float kdOnly = 0.7f * glm::dot(glm::normalize(glm::vec3(-0.5f, 0, -5)), glm::vec3(0, 0, -1));
  EXPECT_GT(centre.x, s.materials[0].ka.x + 0.5f * kdOnly);
  LightOptions off;
  off.defaultLight = false;
  ts.lights = resolveLights(s, off);
  t.render(ts, img);
  EXPECT_NEAR(img.pixels[8 * 16 + 8].x, 0.0f, 1e-6f);  // Phong's ambient is Ka x each light: none
}

// A course scene as the course ships it (no mtllib; NAME.mtl beside the OBJ; a "light" material): lit by
// its own ceiling light from the default pose, with shadows that darken and never brighten.
TEST(Tracer, CourseSceneTracesLitWithShadows) {
  const Scene s = loadScene(rtr::test::sourceDir() / "assets-src/rt/cornell_box.obj");
  const LightRig rig = resolveLights(s);
  ASSERT_EQ(rig.lights.size(), 1u);
  EXPECT_EQ(rig.lights[0].kind, Light::Kind::Area);
  EXPECT_GT(rig.lights[0].color.x, 0.0f) << "the light's Ke came from cornell_box.mtl";
  EXPECT_TRUE(rig.note.empty()) << rig.note;
  const Tracer t(s);
  TraceSettings ts;
  ts.width = 64;
  ts.height = 48;
  ts.lens.fovYDeg = 80.0f;
  ImageF on, off;
  t.render(ts, on);
  ts.shadows = false;
  t.render(ts, off);
  double mean = 0.0;
  int darker = 0;
  for (size_t i = 0; i < on.pixels.size(); ++i) {
    mean += on.pixels[i].x + on.pixels[i].y + on.pixels[i].z;
    EXPECT_LE(on.pixels[i].x, off.pixels[i].x + 1e-6f) << "a shadow brightened pixel " << i;
    darker += on.pixels[i].x < off.pixels[i].x - 0.02f;
  }
  mean /= 3.0 * double(on.pixels.size());
  EXPECT_GT(mean, 0.1) << "lit, not black";
  EXPECT_GT(darker, 20) << "the blocks cast shadows";
}

TEST(Tracer, ShadowGivesAmbientAndEmissiveOnly) {
  Scene s = litPlane({0, 0, 0}, 4.0f, 4);
  const uint32_t mat = addMaterial(s, phong(glm::vec3(0.2f, 0.4f, 0.6f)));
  // A blocker between the light (at 0.4, 0.8, 2.8) and the plane point (0.4, 0.8, 0) below it.
  addMesh(s, box({0.2f, 0.6f, 1.0f}, {0.6f, 1.0f, 1.2f}, mat));
  const Tracer t(s);
  TraceSettings ts;
  const Ray down{{0.4f, 0.8f, 0.5f}, {0, 0, -1}};
  const Ray away{{-1.5f, -1.5f, 0.5f}, {0, 0, -1}};
  const glm::vec3 expectShadow = s.materials[0].ka * 1.0f + s.materials[0].ke;
  const glm::vec3 inShadow = t.traceAndShade(down, 0, ts);
  EXPECT_NEAR(inShadow.x, expectShadow.x, 1e-6f);
  EXPECT_NEAR(inShadow.y, expectShadow.y, 1e-6f);
  EXPECT_GT(t.traceAndShade(away, 0, ts).x, expectShadow.x + 0.1f);
  ts.shadows = false;
  EXPECT_GT(t.traceAndShade(down, 0, ts).x, expectShadow.x + 0.1f);
}

// Far from the origin and tiny: spawned rays never find their own surface, and a lit plane has no acne
// (with nothing else to cast shadows, shadows on must equal shadows off, pixel for pixel).
TEST(Tracer, NoSelfIntersectionOrAcneAtAnyScale) {
  struct Case {
    glm::vec3 centre;
    float size;
  };
  for (const Case& k : {Case{{0, 0, 0}, 4.0f}, Case{{1e5f, -1e5f, 1e5f}, 10.0f}, Case{{1e5f, 1e5f, -1e5f}, 1000.0f},
                        Case{{0, 0, 0}, 1e-4f}, Case{{0.3f, 0.2f, 0.1f}, 1e-4f}}) {
    Scene s = litPlane(k.centre, k.size, 6);
    const Tracer t(s);
    // Tilt the camera so the plane is seen at a slant as well as head on.
    for (float yaw : {0.0f, 35.0f}) {
      TraceSettings ts;
      ts.width = 48;
      ts.height = 32;
      ts.bounces = 0;
      ts.threads = 2;
      CameraPose pose = t.resolvePose(ts);
      pose.yawDeg = yaw;
      pose.position = k.centre + glm::vec3(std::sin(glm::radians(yaw)), 0.0f, std::cos(glm::radians(yaw))) * (0.9f * k.size);
      ts.pose = pose;
      ImageF on, off;
      t.render(ts, on);
      ts.shadows = false;
      t.render(ts, off);
      int lit = 0;
      for (size_t i = 0; i < on.pixels.size(); ++i) {
        ASSERT_EQ(on.pixels[i], off.pixels[i]) << "acne at pixel " << i << ", scale " << k.size << ", centre " << k.centre.x;
        lit += on.pixels[i].x > 0.2f;
      }
      EXPECT_GT(lit, 100) << k.size;
    }
    // Random points of the plane: shadow rays to the light and mirror rays never hit the plane again.
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 0; i < 2000; ++i) {
      const glm::vec3 target = k.centre + glm::vec3((u(rng) - 0.5f) * k.size, (u(rng) - 0.5f) * k.size, 0.0f) * 0.8f;
      const glm::vec3 d = glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, -0.02f - u(rng)));
      const Ray primary{target - d * (0.3f * k.size), d};  // starts below the light
      const Hit h = t.closestTriangle(primary);
      ASSERT_TRUE(h.hit()) << "scale " << k.size << " ray " << i;
      const SurfacePoint sp = t.surface(primary, h);
      const Ray shadow = spawnRay(sp.position, sp.geomNormal, resolveLights(t.scene()).lights[0].position - sp.position, 1.0f);
      EXPECT_FALSE(t.occluded(shadow)) << "scale " << k.size;
      const Ray mirror = reflectRay(primary, sp.geomNormal, sp.position, sp.geomNormal);
      const Hit again = t.closestTriangle(mirror);
      EXPECT_TRUE(!again.hit() || t.scene().materials[t.scene().meshes[t.surface(mirror, again).mesh].material].name == "light")
          << "scale " << k.size;
      // From underneath too (rays leaving the back face).
      const Ray below = spawnRay(sp.position, sp.geomNormal, -sp.geomNormal + glm::vec3(0.3f, 0, 0));
      EXPECT_FALSE(t.closestTriangle(below).hit()) << "scale " << k.size;
    }
  }
}

// A mirror quad facing a coloured box under a light.
Scene mirrorScene(float m) {
  Scene s = litPlane({0, 0, -3}, 6.0f, 2);
  const uint32_t red = addMaterial(s, phong({0.9f, 0.1f, 0.1f}));
  const uint32_t mirror = addMaterial(s, phong({0.1f, 0.1f, 0.9f}, m, "mirror"));
  addMesh(s, box({-0.5f, -0.5f, -2.5f}, {0.5f, 0.5f, -1.5f}, red));
  addMesh(s, quad({-2, -2, -2.9f}, {4, 0, 0}, {0, 4, 0}, mirror));
  return s;
}

TEST(Tracer, MirrorMixesLocalAndReflectedColour) {
  Scene s = mirrorScene(1.0f);
  const Tracer t(s);
  TraceSettings ts;
  const uint32_t mirrorMat = uint32_t(s.materials.size() - 1);
  int checked = 0;
  for (float x = -1.5f; x <= 1.5f; x += 0.25f) {
    const Ray r{{x, 3.0f, 3.0f}, glm::normalize(glm::vec3(-0.1f * x, -0.3f, -1.0f))};
    const Hit h = t.closestTriangle(r);
    ASSERT_TRUE(h.hit());
    const SurfacePoint sp = t.surface(r, h);
    if (sp.material != &s.materials[mirrorMat]) continue;
    ++checked;
    const Ray refl = reflectRay(r, sp.normal, sp.position, sp.geomNormal);
    s.materials[mirrorMat].mirror = 1.0f;
    const glm::vec3 full = t.traceAndShade(r, 3, ts);
    EXPECT_EQ(full, t.traceAndShade(refl, 2, ts));  // m = 1: exactly the reflection
    s.materials[mirrorMat].mirror = 0.0f;
    const glm::vec3 none = t.traceAndShade(r, 3, ts);
    EXPECT_EQ(none, t.traceAndShade(r, 0, ts));  // m = 0: no reflection at all
    s.materials[mirrorMat].mirror = 0.25f;
    const glm::vec3 mix = t.traceAndShade(r, 3, ts);
    const glm::vec3 expect = 0.75f * none + 0.25f * full;
    EXPECT_NEAR(mix.x, expect.x, 1e-6f);
    EXPECT_NEAR(mix.y, expect.y, 1e-6f);
    EXPECT_NEAR(mix.z, expect.z, 1e-6f);
    EXPECT_NE(full, none);
  }
  EXPECT_GT(checked, 5);
}

TEST(Tracer, ClosedMirrorBoxStopsAtNBounces) {
  Scene s;
  const uint32_t mirror = addMaterial(s, phong(glm::vec3(0.5f), 1.0f, "mirror"));
  const uint32_t light = addMaterial(s, lightMaterial(glm::vec3(1)));
  addMesh(s, box({-2, -2, -2}, {2, 2, 2}, mirror, true));
  addMesh(s, box({-0.1f, 1.5f, -0.1f}, {0.1f, 1.7f, 0.1f}, light));
  const Tracer t(s);
  TraceSettings ts;
  ts.width = ts.height = 16;
  ts.pose = CameraPose{{0.3f, 0.2f, 1.0f}, 10.0f, -5.0f};
  for (int bounces : {0, 1, 3, 7}) {
    ts.bounces = bounces;
    ImageF img;
    const RenderStats st = t.render(ts, img);
    EXPECT_EQ(st.primaryRays, 256u);
    EXPECT_LE(st.reflectionRays, st.primaryRays * uint64_t(bounces));
    EXPECT_GE(st.reflectionRays, st.primaryRays * uint64_t(bounces) * 9 / 10);  // almost every ray keeps going
    for (const glm::vec4& p : img.pixels) EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
  }
}

TEST(Tracer, TilesCoverTheImageOnceAndThreadsAgree) {
  Scene s = mirrorScene(0.5f);
  const Tracer t(s);
  EXPECT_TRUE(t.usesBvh());
  TraceSettings ts;
  ts.width = 69;  // the last tile's rows have an odd pixel: traced alone, the others in pairs
  ts.height = 45;
  ts.tileSize = 16;
  std::vector<int> covered(size_t(ts.width) * ts.height, 0);
  int tiles = 0;
  ImageF a, b;
  ts.threads = 2;
  const RenderStats st = t.render(ts, a, [&](const TileRect& r) {
    ++tiles;
    for (uint32_t y = r.y0; y < r.y1; ++y)
      for (uint32_t x = r.x0; x < r.x1; ++x) ++covered[size_t(y) * ts.width + x];
  });
  EXPECT_EQ(tiles, 5 * 3);
  EXPECT_EQ(st.tilesDone, st.tilesTotal);
  EXPECT_FALSE(st.cancelled);
  for (int c : covered) EXPECT_EQ(c, 1);
  ts.threads = 1;
  t.render(ts, b);
  EXPECT_EQ(a.pixels, b.pixels);
  // Primary rays traced in pairs give each pixel exactly its colour traced alone.
  for (uint32_t y = 0; y < ts.height; ++y)
    for (uint32_t x = 0; x < ts.width; ++x)
      ASSERT_EQ(glm::vec3(a.at(x, y)), t.traceAndShade(t.calculateRay(ts, x, y), ts.bounces, ts)) << x << "," << y;
  // Shadow rays traced as packets (one per light sample, all pixels of a packet at once) change nothing:
  // several samples of the area light, and pbr.
  for (const Shading shading : {Shading::Phong, Shading::Pbr}) {
    TraceSettings t2 = ts;
    t2.shading = shading;
    t2.areaLightSamples = 3;
    ImageF c;
    const RenderStats st2 = t.render(t2, c);
    EXPECT_GT(st2.shadowRays, st2.primaryRays / 10);
    for (uint32_t y = 0; y < t2.height; ++y)
      for (uint32_t x = 0; x < t2.width; ++x)
        ASSERT_EQ(glm::vec3(c.at(x, y)), t.traceAndShade(t.calculateRay(t2, x, y), t2.bounces, t2)) << x << "," << y;
  }
  // Cancel from the first tile's callback: the render stops early.
  std::atomic<bool> cancel{false};
  const RenderStats cst = t.render(
      ts, b, [&](const TileRect&) { cancel = true; }, &cancel);
  EXPECT_TRUE(cst.cancelled);
  EXPECT_LT(cst.tilesDone, cst.tilesTotal);
  // Bad settings are errors, not crashes.
  ts.width = 0;
  EXPECT_THROW(t.render(ts, b), Error);
}

TEST(Tracer, CameraRaysAndModelTransform) {
  Scene s = mirrorScene(0.0f);
  const Tracer t(s);
  TraceSettings ts;
  ts.width = 101;
  ts.height = 51;
  ts.pose = CameraPose{{0, 0, 5}, 0, 0};
  const Ray centre = t.calculateRay(ts, 50, 25);
  EXPECT_NEAR(centre.direction.z, -1.0f, 1e-6f);
  // Corner rays open to the lens' field of view.
  const Ray top = t.calculateRay(ts, 50, 0);
  const float halfFov = std::atan2(top.direction.y, -top.direction.z);
  EXPECT_NEAR(halfFov, glm::radians(ts.lens.fovYDeg * 0.5f) * (50.0f / 51.0f), 2e-3f);
  // Orthographic: parallel rays whose origins span ±aspect·h × ±h.
  ts.lens.orthographic = true;
  const Ray o0 = t.calculateRay(ts, 0, 0), o1 = t.calculateRay(ts, 100, 50);
  EXPECT_EQ(o0.direction, o1.direction);
  EXPECT_NEAR(o1.origin.x - o0.origin.x, 2.0f * (101.0f / 51.0f) * (100.0f / 101.0f), 1e-4f);
  ts.lens.orthographic = false;
  // Moving the model by +x looks like moving the camera by −x: same image (modelview = view × model).
  ts.width = ts.height = 24;
  ImageF a, b;
  ts.model = glm::translate(glm::mat4(1.0f), glm::vec3(0.5f, 0, 0));
  t.render(ts, a);
  ts.model = glm::mat4(1.0f);
  ts.pose->position.x -= 0.5f;
  t.render(ts, b);
  for (size_t i = 0; i < a.pixels.size(); ++i) EXPECT_NEAR(glm::distance(a.pixels[i], b.pixels[i]), 0.0f, 1e-4f);
  EXPECT_EQ(modelview(*ts.pose, ts.model), viewMatrix(*ts.pose));
}

// Without a pose the tracer starts where rtr-view does: the scene's stored view, else the bounds framed.
TEST(Tracer, DefaultPoseIsTheViewersStartPose) {
  Scene s = mirrorScene(0.0f);
  TraceSettings ts;
  ts.width = 64;
  ts.height = 32;
  const CameraPose framed = frameBounds(s.bounds(), ts.lens, 2.0f);
  {
    const Tracer t(s);
    const CameraPose p = t.resolvePose(ts);
    EXPECT_EQ(p.position, framed.position);
    EXPECT_EQ(p.yawDeg, framed.yawDeg);
    EXPECT_EQ(p.pitchDeg, framed.pitchDeg);
  }
  s.defaultView = CameraPose{{1.0f, 2.0f, 3.0f}, 40.0f, -15.0f};
  const Tracer t(s);
  const CameraPose p = t.resolvePose(ts);
  EXPECT_EQ(p.position, s.defaultView->position);
  EXPECT_EQ(p.yawDeg, 40.0f);
  EXPECT_EQ(p.pitchDeg, -15.0f);
  ts.pose = CameraPose{{0, 0, 9}, 0, 0};  // --camera wins over both
  EXPECT_EQ(t.resolvePose(ts).position, glm::vec3(0, 0, 9));
}

TEST(Tracer, DebugViewsAndTinyScenes) {
  Scene s;
  const uint32_t m = addMaterial(s, phong(glm::vec3(0.5f)));
  addMesh(s, quad({-1, -1, -2}, {2, 0, 0}, {0, 2, 0}, m));
  const Tracer t(s);
  EXPECT_FALSE(t.usesBvh());  // two triangles: the brief's loop
  TraceSettings ts;
  ts.width = ts.height = 8;
  ts.pose = CameraPose{{0, 0, 0}, 0, 0};
  ts.shading = Shading::Normals;
  ImageF img;
  t.render(ts, img);
  // |n| = (0,0,1), stored so that the sRGB file shows the value itself.
  EXPECT_NEAR(linearToSrgb(img.at(4, 4).z), 1.0f, 1e-5f);
  EXPECT_NEAR(img.at(4, 4).x, 0.0f, 1e-6f);
  ts.shading = Shading::Depth;
  t.render(ts, img);
  const float d = linearToSrgb(img.at(4, 4).x);
  EXPECT_GT(d, 0.0f);
  EXPECT_LT(d, 1.0f);
}

}  // namespace
}  // namespace rtr::trace
