// Alpha-masked, two-sided geometry: texels below alpha 0.5 are not drawn, and both faces are lit.
#include <gtest/gtest.h>

#include "core/image.hpp"
#include "render/headless.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

// A 2×2 quad at z = 0 whose texture is opaque on the right half (u > 0.5) and transparent on the left.
Scene maskedQuad(const std::filesystem::path& dir) {
  ImageRGBA8 tex{8, 8, std::vector<uint8_t>(8 * 8 * 4)};
  for (uint32_t y = 0; y < 8; ++y)
    for (uint32_t x = 0; x < 8; ++x) {
      uint8_t* p = tex.at(x, y);
      p[0] = 200, p[1] = 180, p[2] = 160, p[3] = x >= 4 ? 255 : 40;
    }
  savePng(dir / "leaf.png", tex);
  Scene s;
  s.baseDir = dir;
  s.textures.push_back({"leaf.png", true, 4});
  Material m;
  m.name = "leaf.DoubleSided";
  m.flags = kMaterialAlphaMasked | kMaterialDoubleSided;
  m.textures[uint32_t(TextureSlot::BaseColor)] = 0;
  m.textures[uint32_t(TextureSlot::AlphaMask)] = 0;
  m.roughness = 1.0f;
  s.materials.push_back(m);
  Mesh q;
  q.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  q.normals.assign(4, glm::vec3(0, 0, 1));
  q.texcoords = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  q.indices = {0, 1, 2, 0, 2, 3};
  for (auto& p : q.positions) q.bounds.extend(p);
  s.meshes.push_back(q);
  return s;
}

using test::VulkanTest;

TEST_F(VulkanTest, AlphaMaskedQuadDiscardsAndLightsBothFaces) {
  auto dir = std::filesystem::temp_directory_path() / "rtr_alpha_test";
  std::filesystem::create_directories(dir);
  Scene scene = maskedQuad(dir);
  {
    render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
    ASSERT_TRUE(gpu.hasDraws(render::DrawKind::AlphaMasked));
    EXPECT_FALSE(gpu.hasDraws(render::DrawKind::Opaque)) << "no opaque pipeline for a scene without opaque meshes";
    render::HeadlessRenderer r(*ctx, gpu, {64, 64});
    render::RenderSettings s;
    s.mosaic = render::MosaicMode::Off;
    s.lights.ambient = glm::vec3(0.0f);  // lit only by the light: an unlit face would be black
    Lens lens;
    lens.fovYDeg = 60.0f;
    for (auto [path, raster] : {std::pair{render::ShadingPath::Forward, render::RasterPath::Auto},
                                {render::ShadingPath::Visibility, render::RasterPath::Hardware},
                                {render::ShadingPath::Visibility, render::RasterPath::Compute}}) {
      s.shading = path;
      s.raster = raster;
      for (bool back : {false, true}) {
        SCOPED_TRACE(testing::Message() << rtr::enumName(path) << ", " << rtr::enumName(raster) << (back ? " back" : " front"));
        CameraPose pose{{0, 0, back ? -2.5f : 2.5f}, back ? 180.0f : 0.0f, 0.0f};
        s.lights.lights = {Light{}};
        s.lights.lights[0].position = pose.position;
        render::HeadlessFrame f = r.render(pose, lens, s);
        // Seen from the back, the texture's opaque half (u > 0.5, world x > 0) appears on the image's left.
        const uint32_t opaqueX = back ? 22 : 42, clearX = back ? 42 : 22;
        const uint8_t* lit = f.image.at(opaqueX, 32);
        const uint8_t* hole = f.image.at(clearX, 32);
        EXPECT_GT(lit[0], 60) << "face not lit";
        EXPECT_EQ(hole[0] + hole[1] + hole[2], 0) << "alpha < 0.5 texel was drawn";
      }
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rtr
