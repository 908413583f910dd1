// The renderer's pipelines made while the scene uploads (render/startup.hpp PipelinesAhead, docs/startup.md
// "Phases side by side"): the scene's kinds computed from the Scene are those of the upload; the pipelines
// made from them ahead are every pipeline a first frame makes, in every path, and draw what pipelines made
// by the frame draw; a failure beside them waits for their thread before anything goes.
#include <filesystem>
#include <memory>
#include <stdexcept>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "render/cull.hpp"
#include "render/headless.hpp"
#include "render/startup.hpp"
#include "scene/framing.hpp"
#include "scene/load.hpp"
#include "test_paths.hpp"
#include "vk/pipeline_cache.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

namespace fs = std::filesystem;
using test::VulkanTest;

Mesh quad(float x0, float x1, float y0, float y1, float z, uint32_t material, bool texcoords) {
  Mesh q;
  q.material = material;
  q.positions = {{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}};
  q.normals.assign(4, glm::vec3(0, 0, 1));
  if (texcoords) q.texcoords = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  q.indices = {0, 1, 2, 0, 2, 3};
  for (auto& p : q.positions) q.bounds.extend(p);
  return q;
}

// The temple with what its kinds do not show: an untextured quad, a blended glTF quad (the transparency
// pass, material extras; `blended`), a mesh with texcoords and no triangles, and instances placing some
// meshes twice (one mirrored) and the alpha-masked and two-sided ones not at all.
Scene mixedTemple(bool blended) {
  Scene s = loadScene(test::assetDir() / "temple.rtrscene");
  const uint32_t plain = uint32_t(s.materials.size()), blend = plain + 1;
  s.materials.push_back(Material{});
  Material glass;
  glass.flags = kMaterialGltf | kMaterialBlend;
  glass.opacity = 0.5f;
  s.materials.push_back(glass);
  s.meshes.push_back(quad(-1, 1, 0, 2, 0, plain, false));
  if (blended) s.meshes.push_back(quad(-1, 1, 0, 2, 1, blend, true));
  Mesh empty = quad(0, 1, 0, 1, 0, plain, true);
  empty.indices.clear();
  s.meshes.push_back(std::move(empty));
  for (uint32_t m = 0; m < s.meshes.size(); ++m) {
    if (render::clusterFlags(s.meshes[m], s.materials.at(s.meshes[m].material))) continue;  // never placed
    s.instances.push_back({m, glm::mat4(1.0f)});
    if (m % 3 == 0) s.instances.push_back({m, glm::scale(glm::mat4(1.0f), glm::vec3(-1, 1, 1))});
  }
  return s;
}

void expectSameKinds(const render::SceneKinds& before, const render::SceneKinds& uploaded, const std::string& what) {
  for (size_t k = 0; k < render::kDrawKindCount; ++k)
    EXPECT_EQ(before.draws[k], uploaded.draws[k]) << what << ": draw kind " << k;
  EXPECT_EQ(before.blended, uploaded.blended) << what;
  EXPECT_EQ(before.texcoords, uploaded.texcoords) << what;
  EXPECT_EQ(before.materialExtras, uploaded.materialExtras) << what;
  EXPECT_EQ(before.textures, uploaded.textures) << what;
  EXPECT_EQ(before.instances, uploaded.instances) << what;
  EXPECT_EQ(before.triangles, uploaded.triangles) << what;
  EXPECT_EQ(before.visIds, uploaded.visIds) << what;
  EXPECT_EQ(before.clusterIdsFit, uploaded.clusterIdsFit) << what;
  EXPECT_TRUE(before == uploaded) << what;
}

// Scenes nobody here wrote (Debian's assimp-testmodels) and our own, each field told apart somewhere.
TEST_F(VulkanTest, SceneKindsAreWhatTheUploadMakes) {
  const Scene mixed = mixedTemple(true);
  const render::SceneKinds k = render::sceneKinds(mixed);
  EXPECT_TRUE(k.blended && k.materialExtras && k.texcoords && k.textures > 0);
  EXPECT_TRUE(k.draws[size_t(render::DrawKind::Opaque)] && k.draws[size_t(render::DrawKind::Untextured)]);
  EXPECT_FALSE(k.draws[size_t(render::DrawKind::AlphaMasked)]) << "the masked meshes are placed by no instance";
  EXPECT_TRUE(render::sceneKinds(loadScene(test::assetDir() / "temple.rtrscene")).draws[size_t(render::DrawKind::AlphaMasked)]);
  {
    const render::GpuScene gpu(*ctx, mixed, render::MipMode::Auto, {}, render::GeometryUpload::Auto,
                               render::TextureLoad::Deferred);
    expectSameKinds(k, gpu.kinds(), "the mixed temple");
  }
  std::vector<fs::path> files = {test::assetDir() / "temple.rtrscene"};
  const fs::path assimp = "/usr/share/assimp/models";
  for (const char* f : {"OBJ/box.obj", "OBJ/spider.obj", "OBJ/WusonOBJ.obj", "OBJ/cube_usemtl.obj",
                        "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb",
                        "glTF2/textureTransform/TextureTransformTest.gltf", "glTF2/BoxTextured-glTF/BoxTextured.gltf"})
    if (fs::exists(assimp / f)) files.push_back(assimp / f);
  for (const fs::path& f : files) {
    const Scene scene = loadScene(f);
    const render::GpuScene gpu(*ctx, scene, render::MipMode::Auto, {}, render::GeometryUpload::Auto,
                               render::TextureLoad::Deferred);
    expectSameKinds(render::sceneKinds(scene), gpu.kinds(), f.string());
  }
}

struct Case {
  const char* what;
  render::ShadingPath path;
  render::RasterPath raster;
  int mode;
  render::MosaicMode mosaic;
  bool environment;
};

// Every path a first frame can take: its pipelines made ahead (on a thread, while the scene uploads) are
// all it uses (none is made once the renderer exists), and its image is the one of a renderer that made
// its own. (A scene with blended surfaces makes its transparency pass's pipelines with the renderer.)
TEST_F(VulkanTest, PipelinesMadeAheadAreEveryPipelineTheFirstFrameUses) {
  const Scene scene = mixedTemple(false);
  const CameraPose pose = scene.defaultView.value_or(frameBounds(scene.bounds(), Lens{}, 16.0f / 9.0f));
  const Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
  const auto env = std::make_shared<const render::EnvironmentMaps>(
      *ctx, Environment(ImageF{64, 32, std::vector<glm::vec4>(64 * 32, glm::vec4(0.5f))}, 1.0f, 0.0f));
  using render::MosaicMode, render::RasterPath, render::ShadingPath;
  const Case cases[] = {
      {"forward, mosaic", ShadingPath::Forward, RasterPath::Auto, VIEW_SHADED, MosaicMode::Compute, false},
      {"forward, environment and backdrop", ShadingPath::Forward, RasterPath::Auto, VIEW_SHADED, MosaicMode::Off, true},
      {"a debug view", ShadingPath::Forward, RasterPath::Auto, VIEW_NORMAL, MosaicMode::Off, false},
      {"visibility by the hardware", ShadingPath::Visibility, RasterPath::Hardware, VIEW_SHADED, MosaicMode::Off, false},
      {"visibility by compute, environment", ShadingPath::Visibility, RasterPath::Compute, VIEW_SHADED, MosaicMode::Compute,
       true},
  };
  for (const Case& c : cases) {
    render::RenderSettings s;
    s.shading = c.path;
    s.raster = c.raster;
    s.mode = c.mode;
    s.mosaic = c.mosaic;
    const vk::PipelineStats aheadBefore = ctx->pipelineCache().besideStats();
    render::PipelinesAhead ahead(*ctx, scene, s, c.environment);
    const render::GpuScene gpu(*ctx, scene, render::MipMode::Auto);
    render::Renderer::Prepared prepared = ahead.take();
    EXPECT_GT(ctx->pipelineCache().besideStats().created, aheadBefore.created) << c.what;
    const uint32_t before = ctx->pipelineCache().stats().created;
    render::HeadlessRenderer made(*ctx, gpu, {160, 90}, std::move(prepared));
    made.renderer().setEnvironment(c.environment ? env : nullptr);
    const ImageRGBA8 image = made.render(pose, lens, s).image;
    EXPECT_EQ(ctx->pipelineCache().stats().created, before) << c.what << ": the first frame made a pipeline not made ahead";
    render::HeadlessRenderer own(*ctx, gpu, {160, 90});
    own.renderer().setEnvironment(c.environment ? env : nullptr);
    EXPECT_TRUE(own.render(pose, lens, s).image.pixels == image.pixels) << c.what;
  }
}

// Made for another scene's kinds (here: without its textures), none is taken: the renderer makes its own
// and draws what it draws without them.
TEST_F(VulkanTest, PipelinesMadeForOtherKindsAreNotTaken) {
  const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
  render::SceneKinds other = render::sceneKinds(scene);
  other.textures = 1;
  render::RenderSettings s;
  s.shading = render::ShadingPath::Forward;
  const render::GpuScene gpu(*ctx, scene, render::MipMode::Auto);
  const CameraPose pose = scene.defaultView.value_or(frameBounds(scene.bounds(), Lens{}, 16.0f / 9.0f));
  const Lens lens = fitDepthRange(Lens{}, scene.bounds(), pose);
  const uint32_t before = ctx->pipelineCache().stats().created;
  render::HeadlessRenderer r(*ctx, gpu, {160, 90}, render::Renderer::prepare(*ctx, other, s, false));
  const uint32_t prepared = ctx->pipelineCache().stats().created - before;
  const ImageRGBA8 image = r.render(pose, lens, s).image;
  EXPECT_GT(ctx->pipelineCache().stats().created, before + prepared) << "a pipeline made for other kinds was taken";
  render::HeadlessRenderer own(*ctx, gpu, {160, 90});
  EXPECT_TRUE(own.render(pose, lens, s).image.pixels == image.pixels);
}

// The upload (or anything else on the caller's side) fails while the pipelines are being made: the
// thread is waited for before the scene and the device go (a thread left running would make pipelines
// on a destroyed device: a crash or validation messages).
TEST(PipelinesAhead, AFailureBesideItWaitsForTheThreadBeforeTheDeviceGoes) {
  test::pinDriver();
  vk::Context::resetValidationMessageCount();
  bool failed = false;
  try {
    vk::Context ctx(test::validatedOptions());
    const Scene scene = loadScene(test::assetDir() / "temple.rtrscene");
    render::RenderSettings s;
    s.shading = render::ShadingPath::Visibility;
    s.raster = render::RasterPath::Compute;
    const render::PipelinesAhead ahead(ctx, scene, s, false);
    throw std::runtime_error("the upload failed");
  } catch (const std::runtime_error&) { failed = true; }
  EXPECT_TRUE(failed);
  EXPECT_EQ(vk::Context::validationMessageCount(), 0u);
}

}  // namespace
}  // namespace rtr
