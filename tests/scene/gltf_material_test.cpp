// The glTF reader's materials, textures, samplers and images, cameras and KHR_lights_punctual, and the
// shared texture decoding of images held in memory with a channel chosen.
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/image.hpp"
#include "gltf_builder.hpp"
#include "scene/load.hpp"
#include "scene/textures.hpp"

using namespace rtr;
using rtr::test::GltfBuilder;
using ::testing::HasSubstr;

namespace {

const std::vector<glm::vec3> kTri = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};

// A 2x1 PNG: pixel 0 = (10, 20, 30, 40), pixel 1 = (50, 60, 70, 80).
std::string pngBytes(const std::filesystem::path& dir) {
  ImageRGBA8 img{2, 1, {10, 20, 30, 40, 50, 60, 70, 80}};
  savePng(dir / "px.png", img);
  return test::readFile(dir / "px.png");
}

struct Fixture {
  std::filesystem::path dir;
  GltfBuilder b;
  int pos = 0;
  std::string mesh;
  explicit Fixture(const std::string& name) : dir(test::tempFolder(name)) {
    pos = b.floats(kTri, "VEC3");
    const int nrm = b.floats(std::vector<glm::vec3>(3, {0, 0, 1}), "VEC3");
    const int uv = b.floats(std::vector<glm::vec2>{{0, 0}, {1, 0}, {0, 1}}, "VEC2");
    mesh = "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":" + std::to_string(nrm) +
           ",\"TEXCOORD_0\":" + std::to_string(uv) + "},\"material\":0}]}],\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]";
  }
};

TEST(GltfMaterials, MetallicRoughnessAllSlotsFactorsAndFlags) {
  Fixture f("mr");
  const std::string png = pngBytes(f.dir);
  const int iv = f.b.view(png.data(), png.size());
  const std::string rest =
      f.mesh + ",\"images\":[{\"bufferView\":" + std::to_string(iv) + ",\"mimeType\":\"image/png\"},{\"uri\":\"px.png\"}]," +
      "\"samplers\":[{\"magFilter\":9728,\"minFilter\":9985,\"wrapS\":33071,\"wrapT\":33648}],"
      "\"textures\":[{\"source\":0,\"sampler\":0},{\"source\":1}],"
      "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.25,1,0.75],\"metallicFactor\":0.3,\"roughnessFactor\":0.6,"
      "\"baseColorTexture\":{\"index\":0},\"metallicRoughnessTexture\":{\"index\":1}},"
      "\"normalTexture\":{\"index\":1,\"scale\":0.5},\"occlusionTexture\":{\"index\":1,\"strength\":0.25},"
      "\"emissiveTexture\":{\"index\":0,\"extensions\":{\"KHR_texture_transform\":{\"offset\":[0.5,0],\"rotation\":1.5,\"scale\":[2,3],\"texCoord\":1}}},"
      "\"emissiveFactor\":[1,0.5,0],\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":4},\"KHR_materials_unlit\":{}},"
      "\"alphaMode\":\"MASK\",\"alphaCutoff\":0.3,\"doubleSided\":true}]";
  const Scene s = loadScene(f.b.writeGlb(f.dir, "m", rest));
  const Material& m = s.materials.at(s.meshes.at(0).material);
  EXPECT_EQ(m.flags, kMaterialGltf | kMaterialAlphaMasked | kMaterialDoubleSided | kMaterialUnlit);
  EXPECT_EQ(m.baseColor, glm::vec3(0.5f, 0.25f, 1.0f));
  EXPECT_FLOAT_EQ(m.opacity, 0.75f);
  EXPECT_FLOAT_EQ(m.metalness, 0.3f);
  EXPECT_FLOAT_EQ(m.roughness, 0.6f);
  EXPECT_FLOAT_EQ(m.alphaCutoff, 0.3f);
  EXPECT_FLOAT_EQ(m.normalScale, 0.5f);
  EXPECT_FLOAT_EQ(m.occlusionStrength, 0.25f);
  EXPECT_EQ(m.emissive, glm::vec3(4, 2, 0));
  auto tex = [&](TextureSlot slot) { return s.textures.at(m.texture(slot)); };
  // Base colour: embedded, sRGB, sampler 0.
  EXPECT_TRUE(tex(TextureSlot::BaseColor).bytes);
  EXPECT_TRUE(tex(TextureSlot::BaseColor).srgb);
  EXPECT_EQ(tex(TextureSlot::BaseColor).sampler, (SamplerDesc{Wrap::ClampToEdge, Wrap::MirroredRepeat, true, false, true}));
  // The mask: the base colour image's alpha.
  EXPECT_EQ(tex(TextureSlot::AlphaMask).bytes, tex(TextureSlot::BaseColor).bytes);
  EXPECT_EQ(tex(TextureSlot::AlphaMask).sourceChannel, 4);
  // The metal-rough texture: the same external image twice, G for roughness and B for metalness, linear.
  EXPECT_EQ(tex(TextureSlot::Roughness).path, "px.png");
  EXPECT_EQ(tex(TextureSlot::Roughness).sourceChannel, 2);
  EXPECT_EQ(tex(TextureSlot::Metalness).sourceChannel, 3);
  EXPECT_EQ(tex(TextureSlot::Metalness).channels, 1);
  EXPECT_FALSE(tex(TextureSlot::Roughness).srgb);
  EXPECT_EQ(tex(TextureSlot::Occlusion).sourceChannel, 1);
  EXPECT_EQ(tex(TextureSlot::NormalMap).channels, 4);
  EXPECT_FALSE(tex(TextureSlot::NormalMap).srgb);
  EXPECT_EQ(tex(TextureSlot::Emissive).sampler, tex(TextureSlot::BaseColor).sampler);
  const UvTransform& t = m.uv[uint32_t(TextureSlot::Emissive)];
  EXPECT_EQ(t.offset, glm::vec2(0.5f, 0.0f));
  EXPECT_FLOAT_EQ(t.rotation, 1.5f);
  EXPECT_EQ(t.scale, glm::vec2(2, 3));
  EXPECT_EQ(t.texCoord, 1u);
  EXPECT_TRUE(m.uv[uint32_t(TextureSlot::BaseColor)].identity());
  // Tangents were generated for the normal map (the primitive has none).
  EXPECT_EQ(s.meshes[0].tangents.size(), s.meshes[0].positions.size());

  // Decoding: the roughness slot is the G channel of the image, the mask the A channel of the embedded one.
  EXPECT_EQ(decodeTexture(s, tex(TextureSlot::Roughness)).texels, (std::vector<uint8_t>{20, 60}));
  EXPECT_EQ(decodeTexture(s, tex(TextureSlot::Metalness)).texels, (std::vector<uint8_t>{30, 70}));
  EXPECT_EQ(decodeTexture(s, tex(TextureSlot::AlphaMask)).texels, (std::vector<uint8_t>{40, 80}));
  // Occlusion is the R channel, not the image's luminance (R 10/50, G 20/60, B 30/70).
  EXPECT_EQ(decodeTexture(s, tex(TextureSlot::Occlusion)).texels, (std::vector<uint8_t>{10, 50}));
  // glTF materials sample the normal map and occlusion; an OBJ-style material with the same slots does not.
  const std::vector<uint32_t> used = sampledTextures(s);
  EXPECT_NE(std::find(used.begin(), used.end(), m.texture(TextureSlot::NormalMap)), used.end());
  EXPECT_NE(std::find(used.begin(), used.end(), m.texture(TextureSlot::Occlusion)), used.end());
  Scene obj = s;
  obj.materials[s.meshes[0].material].flags &= ~kMaterialGltf;
  obj.materials[s.meshes[0].material].textures[uint32_t(TextureSlot::Roughness)] = kNoTexture;
  obj.materials[s.meshes[0].material].textures[uint32_t(TextureSlot::Metalness)] = kNoTexture;
  const std::vector<uint32_t> objUsed = sampledTextures(obj);
  EXPECT_EQ(std::find(objUsed.begin(), objUsed.end(), m.texture(TextureSlot::NormalMap)), objUsed.end());
}

TEST(GltfMaterials, DefaultMaterialBlendAndDataUriImage) {
  Fixture f("blend");
  const std::string png = pngBytes(f.dir);
  const std::string rest =
      f.mesh + ",\"images\":[{\"uri\":\"data:image/png;base64," + test::base64(png) +
      "\"}],\"textures\":[{\"source\":0}],"
      "\"materials\":[{\"alphaMode\":\"BLEND\",\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}]";
  const Scene s = loadScene(f.b.writeGltf(f.dir, "b", rest));
  const Material& m = s.materials.at(s.meshes.at(0).material);
  EXPECT_EQ(m.flags, kMaterialGltf | kMaterialBlend);
  EXPECT_FLOAT_EQ(m.metalness, 1.0f);  // the spec's default
  EXPECT_EQ(decodeTexture(s, s.textures.at(m.texture(TextureSlot::BaseColor))).texels,
            (std::vector<uint8_t>{10, 20, 30, 40, 50, 60, 70, 80}));
  // A primitive without a material gets the spec's default material.
  Fixture g("default");
  const std::string noMat = "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0}]";
  const Scene d = loadScene(g.b.writeGlb(g.dir, "d", noMat));
  const Material& dm = d.materials.at(d.meshes.at(0).material);
  EXPECT_EQ(dm.flags, kMaterialGltf);
  EXPECT_EQ(dm.baseColor, glm::vec3(1));
  EXPECT_FLOAT_EQ(dm.metalness, 1.0f);
  EXPECT_FLOAT_EQ(dm.roughness, 1.0f);
}

TEST(GltfMaterials, MissingImageFileIsAWarningNamingThePath) {
  Fixture f("missingimg");
  std::vector<std::string> warnings;
  LoadOptions o;
  o.warn = [&](const std::string& s) { warnings.push_back(s); };
  const std::string rest = f.mesh +
                           ",\"images\":[{\"uri\":\"nothere.png\"}],\"textures\":[{\"source\":0}],"
                           "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}]";
  const Scene s = loadScene(f.b.writeGlb(f.dir, "w", rest), o);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_THAT(warnings[0], HasSubstr("w.glb: /images/0/uri: image file 'nothere.png' does not exist"));
  // The renderers show their checker for it (decodeTextures' warning names the file).
  std::vector<std::string> decodeWarnings;
  const uint32_t t = s.materials.at(0).texture(TextureSlot::BaseColor);
  decodeTextures(
      s, std::vector<uint32_t>{t}, [](size_t, TexelData&&) {}, [&](const std::string& w) { decodeWarnings.push_back(w); });
  ASSERT_EQ(decodeWarnings.size(), 1u);
  EXPECT_THAT(decodeWarnings[0], HasSubstr("nothere.png"));
}

TEST(GltfScene, FirstCameraIsTheDefaultViewWithItsFieldOfView) {
  Fixture f("camera");
  // Camera node 1 under node 0 (translation 0,0,5), turned 90° left about y: looks down -x.
  const std::string rest =
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
      "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.5,\"znear\":0.1}},{\"type\":\"perspective\",\"perspective\":{\"yfov\":1.0,\"znear\":0.1}}],"
      "\"nodes\":[{\"mesh\":0,\"translation\":[0,0,5],\"children\":[1]},{\"camera\":0,\"rotation\":[0,0.70710678,0,0.70710678]},{\"camera\":1}],"
      "\"scenes\":[{\"nodes\":[0,2]}]";
  const Scene s = loadScene(f.b.writeGlb(f.dir, "c", rest));
  ASSERT_TRUE(s.defaultView);
  EXPECT_EQ(s.defaultView->position, glm::vec3(0, 0, 5));
  EXPECT_NEAR(s.defaultView->yawDeg, 90.0f, 1e-3);
  EXPECT_NEAR(s.defaultView->pitchDeg, 0.0f, 1e-3);
  EXPECT_NEAR(basis(*s.defaultView).forward.x, -1.0f, 1e-5);
  EXPECT_NEAR(s.defaultFovYDeg, 0.5f * 180.0f / float(M_PI), 1e-4);
}

TEST(GltfScene, PunctualLightsWithColourTimesIntensity) {
  Fixture f("lights");
  const std::string rest =
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
      "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"point\",\"color\":[1,0.5,0],\"intensity\":10,\"range\":7},"
      "{\"type\":\"spot\",\"spot\":{\"innerConeAngle\":0.2,\"outerConeAngle\":0.6}},{\"type\":\"directional\",\"intensity\":3}]}},"
      "\"nodes\":[{\"mesh\":0},{\"translation\":[1,2,3],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},"
      "{\"translation\":[0,4,0],\"rotation\":[-0.70710678,0,0,0.70710678],\"extensions\":{\"KHR_lights_punctual\":{\"light\":1}}},"
      "{\"extensions\":{\"KHR_lights_punctual\":{\"light\":2}}}],\"scenes\":[{\"nodes\":[0,1,2,3]}]";
  const Scene s = loadScene(f.b.writeGlb(f.dir, "l", rest));
  ASSERT_EQ(s.lights.size(), 3u);
  EXPECT_EQ(s.lights[0].kind, Light::Kind::Point);
  EXPECT_EQ(s.lights[0].position, glm::vec3(1, 2, 3));
  EXPECT_EQ(s.lights[0].color, glm::vec3(10, 5, 0));
  EXPECT_TRUE(s.lights[0].falloff);
  EXPECT_FLOAT_EQ(s.lights[0].range, 7.0f);
  EXPECT_EQ(s.lights[1].kind, Light::Kind::Spot);
  EXPECT_TRUE(s.lights[1].falloff);
  EXPECT_NEAR(s.lights[1].direction.y, -1.0f, 1e-5);  // turned -90° about x: -z becomes -y (pointing down)
  EXPECT_FLOAT_EQ(s.lights[1].innerConeCos, std::cos(0.2f));
  EXPECT_FLOAT_EQ(s.lights[1].outerConeCos, std::cos(0.6f));
  EXPECT_EQ(s.lights[2].kind, Light::Kind::Directional);
  EXPECT_FALSE(s.lights[2].falloff);
  EXPECT_EQ(s.lights[2].direction, glm::vec3(0, 0, -1));
  EXPECT_EQ(s.lights[2].color, glm::vec3(3));
}

}  // namespace
