// glTF material factors on the GPU, the same in the forward path and the visibility path on both
// rasterisers: the alpha cutoff against opacity × the one-channel mask (the base colour's alpha), unlit
// materials, and occlusion × strength on the ambient term.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "core/image.hpp"
#include "render/headless.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

constexpr uint32_t kSize = 96;

// Three unit quads side by side at z = 0 (x in [-1.6, -0.6], [-0.5, 0.5], [0.6, 1.6]), facing +z.
Mesh quad(float x0, uint32_t material) {
  Mesh q;
  q.material = material;
  q.positions = {{x0, -0.5f, 0}, {x0 + 1, -0.5f, 0}, {x0 + 1, 0.5f, 0}, {x0, 0.5f, 0}};
  q.normals.assign(4, glm::vec3(0, 0, 1));
  q.texcoords = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  q.indices = {0, 1, 2, 0, 2, 3};
  for (auto& p : q.positions) q.bounds.extend(p);
  return q;
}

Scene gltfScene(const std::filesystem::path& dir, bool withOcclusion) {
  // Base colour: left half alpha 0.6, right half alpha 1 (cut at 0.7 where alpha is 0.6, kept at 0.5).
  ImageRGBA8 base{8, 8, std::vector<uint8_t>(8 * 8 * 4)};
  for (uint32_t y = 0; y < 8; ++y)
    for (uint32_t x = 0; x < 8; ++x) {
      uint8_t* p = base.at(x, y);
      p[0] = 230, p[1] = 200, p[2] = 180, p[3] = x < 4 ? 153 : 255;
    }
  savePng(dir / "base.png", base);
  ImageRGBA8 occ{4, 4, std::vector<uint8_t>(4 * 4 * 4, 64)};  // red 64/255 ≈ 0.25 (linear)
  savePng(dir / "occ.png", occ);
  Scene s;
  s.baseDir = dir;
  s.textures.push_back({"base.png", true, 4});
  Texture mask{"base.png", false, 1};
  mask.sourceChannel = 4;  // glTF's mask: the base colour's alpha
  s.textures.push_back(mask);
  Texture o{"occ.png", false, 1};
  s.textures.push_back(o);

  Material masked;
  masked.name = "masked";
  masked.flags = kMaterialGltf | kMaterialAlphaMasked;
  masked.alphaCutoff = 0.7f;
  masked.textures[uint32_t(TextureSlot::BaseColor)] = 0;
  masked.textures[uint32_t(TextureSlot::AlphaMask)] = 1;
  Material unlit;
  unlit.name = "unlit";
  unlit.flags = kMaterialGltf | kMaterialUnlit;
  unlit.baseColor = glm::vec3(0.2f, 0.6f, 0.9f);
  Material occluded;
  occluded.name = "occluded";
  occluded.flags = kMaterialGltf;
  occluded.baseColor = glm::vec3(0.8f);
  occluded.occlusionStrength = 0.5f;
  if (withOcclusion) occluded.textures[uint32_t(TextureSlot::Occlusion)] = 2;
  s.materials = {masked, unlit, occluded};
  s.meshes = {quad(-1.6f, 0), quad(-0.5f, 1), quad(0.6f, 2)};
  return s;
}

using test::VulkanTest;

TEST_F(VulkanTest, GltfCutoffUnlitAndOcclusionInEveryPath) {
  const auto dir = std::filesystem::temp_directory_path() / "rtr_gltf_material_test";
  std::filesystem::create_directories(dir);
  const Scene scene = gltfScene(dir, true), plain = gltfScene(dir, false);
  {
    render::GpuScene gpu(*ctx, scene, render::MipMode::Compute), gpuPlain(*ctx, plain, render::MipMode::Compute);
    render::HeadlessRenderer r(*ctx, gpu, {kSize, kSize}), rPlain(*ctx, gpuPlain, {kSize, kSize});
    render::RenderSettings s;
    s.mosaic = render::MosaicMode::Off;
    s.lights.lights.clear();  // ambient only: the occlusion's term alone
    s.lights.ambient = glm::vec3(1.0f);
    Lens lens;
    lens.fovYDeg = 60.0f;
    const CameraPose pose{{0, 0, 3.0f}, 0.0f, 0.0f};
    // Pixel columns of the quads' centres: x = -1.1, 0 and 1.1 at distance 3 under a 60° field of view.
    auto column = [](float x) {
      return uint32_t(std::lround((0.5f + 0.5f * x / (3.0f * std::tan(glm::radians(30.0f)))) * kSize));
    };
    for (auto [path, raster] : {std::pair{render::ShadingPath::Forward, render::RasterPath::Auto},
                                {render::ShadingPath::Visibility, render::RasterPath::Hardware},
                                {render::ShadingPath::Visibility, render::RasterPath::Compute}}) {
      SCOPED_TRACE(testing::Message() << enumName(path) << ", " << enumName(raster));
      s.shading = path;
      s.raster = raster;
      const ImageRGBA8 img = r.render(pose, lens, s).image, ref = rPlain.render(pose, lens, s).image;
      const uint32_t y = kSize / 2;
      // The masked quad: its left half (alpha 0.6 < 0.7) is cut out, its right half drawn.
      const uint8_t* cut = img.at(column(-1.1f) - 6, y);
      const uint8_t* kept = img.at(column(-1.1f) + 6, y);
      EXPECT_EQ(cut[0] + cut[1] + cut[2], 0) << "alpha 0.6 under cutoff 0.7 was drawn";
      EXPECT_GT(kept[0], 100) << "alpha 1 was cut";
      // Unlit: the base colour itself, sRGB-encoded, whatever the light.
      const uint8_t* u = img.at(column(0.0f), y);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(u[c], std::lround(linearToSrgb(scene.materials[1].baseColor[c]) * 255.0f), 1) << "channel " << c;
      // Occlusion 0.25 at strength 0.5: ambient x 0.625 against the same material without the texture.
      const uint8_t* o = img.at(column(1.1f), y);
      const uint8_t* n = ref.at(column(1.1f), y);
      const float want = linearToSrgb(0.8f * (1.0f + 0.5f * (64.0f / 255.0f - 1.0f)));
      EXPECT_NEAR(o[1], std::lround(want * 255.0f), 2);
      EXPECT_NEAR(n[1], std::lround(linearToSrgb(0.8f) * 255.0f), 2);
    }
  }
  std::filesystem::remove_all(dir);
}

// Spot and directional lights (KHR_lights_punctual through shaders/shared/lights.h) on a floor seen from
// above: a spot lights its cone and nothing outside the outer cone; a directional light lights the floor
// evenly (no falloff); forward and visibility agree.
TEST_F(VulkanTest, SpotAndDirectionalLightsInEveryPath) {
  Scene scene;
  Material m;
  m.name = "floor";
  m.baseColor = glm::vec3(0.7f);
  m.roughness = 1.0f;
  scene.materials.push_back(m);
  Mesh floor;
  floor.positions = {{-4, 0, -4}, {4, 0, -4}, {4, 0, 4}, {-4, 0, 4}};
  floor.normals.assign(4, glm::vec3(0, 1, 0));
  floor.indices = {0, 2, 1, 0, 3, 2};
  for (auto& p : floor.positions) floor.bounds.extend(p);
  scene.meshes.push_back(floor);
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  render::HeadlessRenderer r(*ctx, gpu, {kSize, kSize});
  Lens lens;
  lens.fovYDeg = 90.0f;
  const CameraPose pose{{0, 3.0f, 0}, 0.0f, -90.0f};  // straight down: the floor fills the view
  render::RenderSettings s;
  s.mosaic = render::MosaicMode::Off;
  s.lights.ambient = glm::vec3(0.0f);
  Light spot;
  spot.kind = Light::Kind::Spot;
  spot.position = {0, 2, 0};
  spot.direction = {0, -1, 0};
  spot.innerConeCos = std::cos(glm::radians(10.0f));
  spot.outerConeCos = std::cos(glm::radians(20.0f));
  spot.color = glm::vec3(4.0f);
  Light sun;
  sun.kind = Light::Kind::Directional;
  sun.direction = glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f));
  sun.color = glm::vec3(2.0f);
  std::vector<ImageRGBA8> images;
  for (auto [path, raster] : {std::pair{render::ShadingPath::Forward, render::RasterPath::Auto},
                              {render::ShadingPath::Visibility, render::RasterPath::Hardware},
                              {render::ShadingPath::Visibility, render::RasterPath::Compute}}) {
    SCOPED_TRACE(testing::Message() << enumName(path) << ", " << enumName(raster));
    s.shading = path;
    s.raster = raster;
    s.lights.lights = {spot};
    const ImageRGBA8 a = r.render(pose, lens, s).image;
    // The floor at distance 3 under 90°: pixel (48 + 16 k) is at x = k / 2 floor units. The cone (20° from
    // height 2) ends at radius 0.73; at radius 1.5 nothing arrives.
    EXPECT_GT(a.at(48, 48)[0], 100) << "the spot's centre is dark";
    EXPECT_EQ(a.at(48 + 48, 48)[0] + a.at(48, 48 + 48 - 1)[0], 0) << "light outside the outer cone";
    s.lights.lights = {sun};
    const ImageRGBA8 b = r.render(pose, lens, s).image;
    EXPECT_NEAR(b.at(10, 10)[0], b.at(85, 85)[0], 6) << "a directional light has no falloff (only the specular moves)";
    EXPECT_GT(b.at(10, 10)[0], 100);
    images.push_back(a);
  }
  for (size_t i = 1; i < images.size(); ++i)
    for (size_t k = 0; k < images[0].pixels.size(); ++k)
      ASSERT_NEAR(images[0].pixels[k], images[i].pixels[k], 2) << "paths disagree at byte " << k;
}

// glTF's per-vertex streams and texture transforms, read from storage buffers by every path: vertex
// colours multiply the base colour, KHR_texture_transform moves a texture, a normal map (with tangents)
// bends the normal.
TEST_F(VulkanTest, VertexColoursTextureTransformAndNormalMapInEveryPath) {
  const auto dir = std::filesystem::temp_directory_path() / "rtr_gltf_stream_test";
  std::filesystem::create_directories(dir);
  ImageRGBA8 halves{2, 1, {255, 0, 0, 255, 0, 0, 255, 255}};  // left red, right blue
  savePng(dir / "halves.png", halves);
  ImageRGBA8 bent{1, 1, {218, 128, 218, 255}};  // tangent-space normal (0.71, 0, 0.71): 45° towards +t
  savePng(dir / "bent.png", bent);
  Scene scene;
  scene.baseDir = dir;
  Texture h{"halves.png", false, 4};
  h.sampler.nearestMag = h.sampler.nearestMin = true;
  scene.textures = {h, Texture{"bent.png", false, 4}};
  Material coloured, shifted, bumpy, flat;
  coloured.flags = shifted.flags = kMaterialGltf | kMaterialUnlit;
  shifted.textures[uint32_t(TextureSlot::BaseColor)] = 0;
  shifted.uv[uint32_t(TextureSlot::BaseColor)].offset = {0.5f, 0.0f};
  bumpy.flags = flat.flags = kMaterialGltf;
  bumpy.baseColor = flat.baseColor = glm::vec3(0.8f);
  bumpy.textures[uint32_t(TextureSlot::NormalMap)] = 1;
  scene.materials = {coloured, shifted, bumpy, flat};
  Mesh a = quad(-1.6f, 0), b = quad(-0.5f, 1), c = quad(0.6f, 2);
  a.colors.assign(4, glm::vec4(0.2f, 0.9f, 0.3f, 1.0f));
  c.tangents.assign(4, glm::vec4(1, 0, 0, 1));
  scene.meshes = {a, b, c};
  Scene plain = scene;
  plain.meshes[2].material = 3;
  {
    render::GpuScene gpu(*ctx, scene, render::MipMode::Compute), gpuFlat(*ctx, plain, render::MipMode::Compute);
    render::HeadlessRenderer r(*ctx, gpu, {kSize, kSize}), rFlat(*ctx, gpuFlat, {kSize, kSize});
    render::RenderSettings s;
    s.mosaic = render::MosaicMode::Off;
    s.lights.ambient = glm::vec3(0.0f);
    Light sun;
    sun.kind = Light::Kind::Directional;
    sun.direction = {0, 0, -1};  // straight onto the quads
    s.lights.lights = {sun};
    Lens lens;
    lens.fovYDeg = 60.0f;
    const CameraPose pose{{0, 0, 3.0f}, 0.0f, 0.0f};
    auto column = [](float x) {
      return uint32_t(std::lround((0.5f + 0.5f * x / (3.0f * std::tan(glm::radians(30.0f)))) * kSize));
    };
    const uint32_t y = kSize / 2;
    for (auto [path, raster] : {std::pair{render::ShadingPath::Forward, render::RasterPath::Auto},
                                {render::ShadingPath::Visibility, render::RasterPath::Hardware},
                                {render::ShadingPath::Visibility, render::RasterPath::Compute}}) {
      SCOPED_TRACE(testing::Message() << enumName(path) << ", " << enumName(raster));
      s.shading = path;
      s.raster = raster;
      const render::HeadlessFrame f = r.render(pose, lens, s, 1, true), g = rFlat.render(pose, lens, s, 1, true);
      const glm::vec4 col = f.sceneColor.pixels[y * kSize + column(-1.1f)];
      EXPECT_NEAR(col.r, 0.2f, 1e-3f);
      EXPECT_NEAR(col.g, 0.9f, 1e-3f) << "vertex colours";
      // Offset 0.5: the quad's left half (u < 0.5) samples the right texel, blue.
      const glm::vec4 left = f.sceneColor.pixels[y * kSize + column(-0.25f)];
      EXPECT_GT(left.b, 0.9f) << "the texture transform's offset was not applied";
      EXPECT_LT(left.r, 0.1f);
      // Lambert under a light along the flat normal: the bent one (45°) gets cos 45° of it.
      const float bentR = f.sceneColor.pixels[y * kSize + column(1.1f)].r,
                  flatR = g.sceneColor.pixels[y * kSize + column(1.1f)].r;
      EXPECT_GT(flatR, 0.1f);
      EXPECT_NEAR(bentR / flatR, 0.707f, 0.08f) << "the normal map did not bend the normal";
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rtr
