// Instances, not copies: a mesh placed by N instances renders exactly as the same scene flattened into N
// transformed meshes (built here on the CPU), in every path: forward, visibility with hardware ids,
// visibility with compute ids, with and without cluster culling; and it is drawn with one instanced draw
// per mesh (and mirroring), not one per instance.
#include <bit>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "core/bounds.hpp"
#include "core/camera.hpp"
#include "render/cull.hpp"
#include "render/headless.hpp"
#include "scene/clusters.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

// A lumpy sphere (so the shading varies over it and its clusters have normal cones), radius about 1.
Mesh lumpySphere(int rings = 16, int segments = 24) {
  Mesh m;
  m.name = "lump";
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s <= segments; ++s) {
      const float th = float(M_PI) * float(r) / rings, ph = 2.0f * float(M_PI) * float(s) / segments;
      const glm::vec3 d(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
      m.positions.push_back(d * (1.0f + 0.15f * std::sin(3.0f * ph) * std::sin(2.0f * th)));
      m.normals.push_back(d);
    }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const uint32_t a = r * (segments + 1) + s, b = a + segments + 1;
      m.indices.insert(m.indices.end(), {a, a + 1, b, a + 1, b + 1, b});  // counter-clockwise from outside
    }
  for (const glm::vec3& p : m.positions) m.bounds.extend(p);
  buildClusters(m, true);
  return m;
}

// 5 x 4 placements whose matrices have one entry per row of 0, ±0.5, ±1 or ±2 and integer translations,
// so that a placed position is one exact product plus one rounded addition on the CPU and on the GPU
// alike; rotations by 90°, uniform and non-uniform scales, and the last four mirrored.
Scene instancedScene() {
  Scene s;
  Material mat;
  mat.name = "lump";
  mat.baseColor = glm::vec3(0.8f, 0.5f, 0.3f);
  mat.roughness = 0.4f;
  s.materials.push_back(mat);
  s.meshes.push_back(lumpySphere());
  for (int i = 0; i < 20; ++i) {
    glm::mat4 t(1.0f);
    t = glm::translate(t, glm::vec3(float(i % 5) * 3.0f - 6.0f, float(i / 5) * 3.0f - 4.5f, float(i % 3) - 1.0f));
    if (i % 4 == 1)
      t = t * glm::mat4(glm::vec4(0, 0, -1, 0), glm::vec4(0, 1, 0, 0), glm::vec4(1, 0, 0, 0), glm::vec4(0, 0, 0, 1));
    if (i % 4 == 2) t = glm::scale(t, glm::vec3(i % 8 == 2 ? 0.5f : 1.0f, 1.0f, 0.5f));  // uniform ones below
    if (i % 7 == 3) t = glm::scale(t, glm::vec3(0.5f));
    if (i % 6 == 5)
      t = t * glm::mat4(glm::vec4(0, 1, 0, 0), glm::vec4(-1, 0, 0, 0), glm::vec4(0, 0, 1, 0), glm::vec4(0, 0, 0, 1));
    if (i >= 16) t = glm::scale(t, glm::vec3(i % 2 ? -1.0f : 1.0f, i % 2 ? 1.0f : -2.0f, 1.0f));  // mirrors
    s.instances.push_back({0, t});
  }
  return s;
}

// The same scene with each instance's mesh transformed on the CPU: positions by the matrix, normals by
// its inverse transpose, a mirrored one's triangles turned round (so counter-clockwise is front again).
Scene flattened(const Scene& in) {
  Scene s;
  s.materials = in.materials;
  for (const Instance& inst : in.instances) {
    Mesh m = in.meshes[inst.mesh];
    const glm::mat3 n = glm::inverseTranspose(glm::mat3(inst.transform));
    m.bounds = {};
    for (glm::vec3& p : m.positions.writable()) p = glm::vec3(inst.transform * glm::vec4(p, 1.0f)), m.bounds.extend(p);
    for (glm::vec3& v : m.normals.writable()) v = n * v;
    if (glm::determinant(glm::mat3(inst.transform)) < 0.0f)
      for (size_t i = 0; i < m.indices.size(); i += 3) std::swap(m.indices.writable()[i + 1], m.indices.writable()[i + 2]);
    m.clusters.clear();  // runs of triangles in order (GpuScene's fallback): the primitive ids stay
    s.meshes.push_back(m);
  }
  return s;
}

class InstanceTest : public test::VulkanTest {};

constexpr VkExtent2D kE{240, 160};

std::vector<CameraPose> views(const Bounds& b) {
  const float aspect = float(kE.width) / float(kE.height);
  return {frameBounds(b, Lens{}, aspect),
          orbitFrame(b, Lens{}, aspect, 150.0f, -20.0f),
          {glm::vec3(0.5f, 0.2f, 4.0f), 10.0f, 5.0f}};  // close, inside the grid: some instances off screen
}

TEST_F(InstanceTest, InstancesDrawLikeTheFlattenedScene) {
  const Scene inst = instancedScene(), flat = flattened(inst);
  render::GpuScene gi(*ctx, inst, render::MipMode::Compute), gf(*ctx, flat, render::MipMode::Compute);
  // One mesh stored once; two instanced draws (plain and mirrored), not one per instance.
  EXPECT_EQ(gi.stats().meshes, 1u);
  EXPECT_EQ(gi.stats().instances, 20u);
  ASSERT_EQ(gi.draws(render::DrawKind::Untextured).size(), 2u);
  EXPECT_EQ(gi.draws(render::DrawKind::Untextured)[0].instanceCount, 16u);
  EXPECT_TRUE(gi.draws(render::DrawKind::Untextured)[1].mirrored);
  render::HeadlessRenderer ri(*ctx, gi, kE), rf(*ctx, gf, kE);
  // The same id ranges: instance i of the one mesh where the flattened scene has mesh i.
  ASSERT_EQ(gi.visIdCount(), gf.visIdCount());

  struct Path {
    render::ShadingPath shading;
    render::RasterPath raster;
    bool cull;
  };
  std::vector<Path> paths = {{render::ShadingPath::Forward, render::RasterPath::Auto, false},
                             {render::ShadingPath::Visibility, render::RasterPath::Hardware, false}};
  if (render::ComputeRaster::supported(*ctx))
    paths.insert(paths.end(), {{render::ShadingPath::Visibility, render::RasterPath::Compute, false},
                               {render::ShadingPath::Visibility, render::RasterPath::Compute, true}});
  const Bounds b = inst.bounds();
  const std::vector<CameraPose> poses = views(b);
  for (const CameraPose& pose : poses) {
    const Lens lens = fitDepthRange(Lens{}, b, pose);
    const bool first = &pose == &poses.front();
    for (const Path& p : paths) {
      SCOPED_TRACE(testing::Message() << "view at " << pose.position.x << ", " << enumName(p.shading) << ", "
                                      << enumName(p.raster) << (p.cull ? ", culled" : ""));
      render::RenderSettings s;
      s.shading = p.shading;
      s.raster = p.raster;
      s.cull = p.cull ? render::Culling::TwoPhase : render::Culling::Off;
      s.mosaic = render::MosaicMode::Off;
      for (int mode : {VIEW_SHADED, VIEW_NORMAL}) {
        if (mode != VIEW_SHADED && p.shading == render::ShadingPath::Visibility) continue;  // debug views are forward
        s.mode = mode;
        const ImageRGBA8 a = ri.render(pose, lens, s, 2).image, c = rf.render(pose, lens, s, 2).image;
        size_t covered = 0, differ = 0;
        int worst = 0;
        for (size_t i = 0; i < a.pixels.size(); ++i) {
          const int d = std::abs(int(a.pixels[i]) - int(c.pixels[i]));
          worst = std::max(worst, d);
          differ += d > 1;
          covered += i % 4 == 0 && (c.pixels[i] | c.pixels[i + 1] | c.pixels[i + 2]) != 0;
        }
        EXPECT_GT(covered, a.pixels.size() / 4 / 20) << "the view sees little";
        // Only the rounding of interpolation in a mirrored triangle's other vertex order differs.
        EXPECT_EQ(differ, 0u) << "mode " << mode << ", worst difference " << worst;
      }
      if (p.shading != render::ShadingPath::Visibility) continue;
      s.mode = VIEW_SHADED;
      const std::vector<uint32_t> a = ri.ids(pose, lens, s), c = rf.ids(pose, lens, s);
      size_t differ = 0, mirroredSeen = 0;
      for (size_t i = 0; i < a.size(); ++i) {
        differ += a[i] != c[i];
        mirroredSeen += a[i] != VIS_EMPTY && gi.decodeVisId(a[i]).first >= 16;
      }
      EXPECT_EQ(differ, 0u) << "visibility ids differ from the flattened scene's";
      if (first) { EXPECT_GT(mirroredSeen, 100u) << "the mirrored instances are not in view"; }
    }
  }
}

// The compute rasteriser's ids (with culling, which must not change them) against the hardware's, on
// the instanced scene: the same up to pixel centres on an edge (tests/render/raster_test.cpp's rule,
// here as a bound on how many pixels differ); culling must have culled something by frustum and cone.
TEST_F(InstanceTest, ComputeIdsEqualHardwareIdsAndCullingChangesNothing) {
  if (!render::ComputeRaster::supported(*ctx)) GTEST_SKIP() << "no 64-bit buffer atomics";
  const Scene inst = instancedScene();
  render::GpuScene g(*ctx, inst, render::MipMode::Compute);
  render::HeadlessRenderer r(*ctx, g, kE), culled(*ctx, g, kE);
  const Bounds b = inst.bounds();
  uint32_t frustum = 0, cone = 0;
  for (const CameraPose& pose : views(b)) {
    const Lens lens = fitDepthRange(Lens{}, b, pose);
    render::RenderSettings s;
    s.mosaic = render::MosaicMode::Off;
    s.raster = render::RasterPath::Hardware;
    const std::vector<uint32_t> hw = r.ids(pose, lens, s);
    s.raster = render::RasterPath::Compute;
    const std::vector<uint32_t> cs = r.ids(pose, lens, s);
    s.cull = render::Culling::TwoPhase;
    culled.ids(pose, lens, s);  // a first frame: history
    const std::vector<uint32_t> cc = culled.ids(pose, lens, s);
    const auto stats = culled.renderer().cullStats(0);
    ASSERT_TRUE(stats.has_value());
    frustum += stats->frustum, cone += stats->cone;
    size_t covered = 0, differ = 0, cullDiffer = 0;
    for (size_t i = 0; i < hw.size(); ++i) {
      covered += hw[i] != VIS_EMPTY;
      differ += hw[i] != cs[i];
      cullDiffer += cc[i] != cs[i];
    }
    std::printf("view at (%.1f %.1f %.1f): %zu px covered, %zu differ hardware/compute; culled by frustum %u, cone %u\n",
                pose.position.x, pose.position.y, pose.position.z, covered, differ, stats->frustum, stats->cone);
    EXPECT_EQ(cullDiffer, 0u) << "culling changed the ids";
    EXPECT_LE(differ, covered / 200) << "compute and hardware ids disagree beyond edge pixels";
  }
  EXPECT_GT(frustum, 0u);
  EXPECT_GT(cone, 0u);
}

// An instance outside the frustum is culled whole: none of its clusters is visited (the culling pass's
// counter), and the frame is the unculled one (ComputeIdsEqualHardwareIdsAndCullingChangesNothing).
TEST_F(InstanceTest, CulledInstancesCostNoClusterTests) {
  if (!render::ComputeRaster::supported(*ctx)) GTEST_SKIP() << "no 64-bit buffer atomics";
  const Scene inst = instancedScene();
  render::GpuScene g(*ctx, inst, render::MipMode::Compute);
  const uint32_t perInstance = uint32_t(inst.meshes[0].clusters.size()), instances = uint32_t(inst.instances.size());
  ASSERT_EQ(g.cullInstanceCount(), instances);
  render::HeadlessRenderer r(*ctx, g, kE);
  render::RenderSettings s;
  s.mosaic = render::MosaicMode::Off;
  s.raster = render::RasterPath::Compute;
  s.cull = render::Culling::TwoPhase;
  const Bounds b = inst.bounds();
  // Looking away from the grid: every instance culled, no cluster tested, nothing drawn.
  const CameraPose away{glm::vec3(0.0f, 0.0f, 20.0f), 180.0f, 0.0f};
  const std::vector<uint32_t> none = r.ids(away, fitDepthRange(Lens{}, b, away), s);
  auto stats = r.renderer().cullStats(0);
  ASSERT_TRUE(stats.has_value());
  EXPECT_EQ(stats->instancesCulled, instances);
  EXPECT_EQ(stats->tested, 0u);
  EXPECT_EQ(std::count(none.begin(), none.end(), VIS_EMPTY), ptrdiff_t(none.size()));
  // Close, inside the grid: some instances culled, the others' clusters tested in both phases.
  const CameraPose close = views(b)[2];
  r.ids(close, fitDepthRange(Lens{}, b, close), s);
  stats = r.renderer().cullStats(0);
  std::printf("close view: %u of %u instances culled whole, %u cluster tests\n", stats->instancesCulled, instances,
              stats->tested);
  EXPECT_GT(stats->instancesCulled, 0u);
  EXPECT_LT(stats->instancesCulled, instances);
  EXPECT_EQ(stats->tested, 2 * (instances - stats->instancesCulled) * perInstance);
}

// Past the old id budget (instance << bits | primitive, bits = 32 - bit_width(instances)): one mesh of
// 40 000 triangles beside 65 536 instances of a one-triangle mesh (a carpet behind it) needs 17 bits
// for the instance and 16 for the primitive. The ids of each instance's range (frame.h) take 105 536:
// the scene stays on the visibility path, hardware and compute ids agree (culling changes nothing), and
// the shaded image is the forward one (tests/render/frame_test.cpp's tolerance), so every id found its
// instance and triangle (the carpet's triangles are tilted by their instance: another one shades otherwise).
TEST_F(InstanceTest, ManyInstancesPastTheOldIdBudgetStayOnTheVisibilityPath) {
  Scene scene;
  Material mat;
  mat.baseColor = glm::vec3(0.8f, 0.5f, 0.3f);
  scene.materials.push_back(mat);
  scene.meshes.push_back(lumpySphere(100, 200));
  Mesh tri;
  tri.positions = {{0, 0, 0}, {0.11f, 0, 0}, {0, 0.11f, 0}};
  tri.normals.assign(3, glm::vec3(0, 0, 1));
  tri.indices = {0, 1, 2};
  for (const glm::vec3& p : tri.positions) tri.bounds.extend(p);
  scene.meshes.push_back(tri);
  scene.instances.push_back({0, glm::mat4(1.0f)});
  for (int i = 0; i < 65536; ++i)
    scene.instances.push_back(
        {1, glm::rotate(
                glm::translate(glm::mat4(1.0f), glm::vec3(0.1f * float(i % 256) - 12.8f, 0.1f * float(i / 256) - 12.8f, -3.0f)),
                0.1f * float(i % 11), glm::vec3(1, 0, 0))});  // tilted: each instance shades its own way
  const uint32_t primitives = uint32_t(scene.meshes[0].indices.size() / 3);
  ASSERT_GT(uint64_t(primitives) << std::bit_width(scene.instances.size()), uint64_t(1) << 32) << "within the old budget";
  render::GpuScene g(*ctx, scene, render::MipMode::Compute);
  EXPECT_EQ(g.visIdCount(), primitives + 65536u);
  render::HeadlessRenderer r(*ctx, g, kE), culled(*ctx, g, kE);
  EXPECT_EQ(r.renderer().visibilityRefusal(), "");
  const Bounds b = scene.bounds();
  size_t sphere = 0;
  for (const CameraPose& pose : {frameBounds(b, Lens{}, 1.5f), CameraPose{glm::vec3(1.0f, 0.5f, 3.5f), 15.0f, -5.0f}}) {
    SCOPED_TRACE(testing::Message() << "view at " << pose.position.x);
    const Lens lens = fitDepthRange(Lens{}, b, pose);
    render::RenderSettings s;
    s.mosaic = render::MosaicMode::Off;
    s.shading = render::ShadingPath::Visibility;
    Light sun;  // bright, so that a wrong instance's tilt would show
    sun.kind = Light::Kind::Directional;
    sun.direction = glm::normalize(glm::vec3(0.3f, -0.5f, -1.0f));
    sun.color = glm::vec3(2.0f);
    s.lights.lights = {sun};
    EXPECT_EQ(r.renderer().pathFor(s), render::ShadingPath::Visibility);
    s.raster = render::RasterPath::Hardware;
    const std::vector<uint32_t> hw = r.ids(pose, lens, s);
    const ImageRGBA8 vis = r.render(pose, lens, s, 1).image;
    s.raster = render::RasterPath::Compute;
    const std::vector<uint32_t> cs = r.ids(pose, lens, s);
    s.cull = render::Culling::TwoPhase;
    culled.ids(pose, lens, s);  // a first frame: history
    const std::vector<uint32_t> cc = culled.ids(pose, lens, s);
    size_t covered = 0, carpet = 0, differ = 0, cullDiffer = 0;
    for (size_t i = 0; i < hw.size(); ++i) {
      covered += hw[i] != VIS_EMPTY;
      carpet += hw[i] != VIS_EMPTY && g.decodeVisId(hw[i]).first > 0;
      differ += hw[i] != cs[i];
      cullDiffer += cc[i] != cs[i];
    }
    EXPECT_GT(carpet, hw.size() / 10) << "the carpet of instances is not in view";
    sphere += covered - carpet;
    EXPECT_LE(differ, covered / 200) << "compute and hardware ids disagree beyond edge pixels";
    EXPECT_EQ(cullDiffer, 0u) << "culling changed the ids";
    s.shading = render::ShadingPath::Forward;
    const ImageRGBA8 fwd = r.render(pose, lens, s, 1).image;
    size_t over = 0;
    int worst = 0;
    for (size_t i = 0; i < fwd.pixels.size(); i += 4) {
      int d = 0;
      for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(fwd.pixels[i + c]) - int(vis.pixels[i + c])));
      worst = std::max(worst, d);
      over += d > 3;
    }
    std::printf("%zu px covered (%zu carpet), %zu differ hardware/compute; shaded: %zu px differ by > 3 from forward, worst %d\n",
                covered, carpet, differ, over, worst);
    EXPECT_LE(over, hw.size() / 200);
    EXPECT_LE(worst, 24);
  }
  EXPECT_GT(sphere, size_t(kE.width) * kE.height / 10) << "the big mesh is not in view";
}

}  // namespace
}  // namespace rtr
