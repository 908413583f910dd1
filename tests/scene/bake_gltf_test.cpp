// rtr-bake with a glTF input: the .rtrscene it writes loads back as the scene the glTF loads as (instances
// kept, samplers, uv transforms, lights), its embedded image written once under a name from its bytes, and
// a different file of that name never overwritten.
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "bake.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "scene/binio.hpp"
#include "scene/load.hpp"
#include "scene_compare.hpp"

namespace fs = std::filesystem;
using namespace rtr;
using ::testing::HasSubstr;

namespace {

std::string base64(const std::vector<uint8_t>& in) {
  static const char* abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < in.size(); i += 3) {
    const uint32_t n =
        uint32_t(in[i]) << 16 | (i + 1 < in.size() ? uint32_t(in[i + 1]) << 8 : 0) | (i + 2 < in.size() ? in[i + 2] : 0);
    for (size_t k = 0; k < 4; ++k) out += i + k <= in.size() ? abc[(n >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

template <class T>
void append(std::vector<uint8_t>& b, std::initializer_list<T> v) {
  for (T x : v) b.insert(b.end(), reinterpret_cast<const uint8_t*>(&x), reinterpret_cast<const uint8_t*>(&x) + sizeof x);
}

struct BakeGltf : ::testing::Test {
  fs::path dir = fs::temp_directory_path() / ("rtr_bake_gltf_" + std::to_string(::getpid()));
  std::vector<uint8_t> png;  // the embedded image
  void SetUp() override {
    fs::remove_all(dir);
    fs::create_directories(dir);
    ImageRGBA8 img{4, 4, {}};
    for (uint32_t i = 0; i < 16; ++i)
      img.pixels.insert(img.pixels.end(), {uint8_t(i * 16), uint8_t(255 - i * 16), uint8_t(i * 5), 255});
    savePng(dir / "img.png", img);
    png = readFileBytes(dir / "img.png");
    fs::remove(dir / "img.png");
    // A quad: positions, normals, uvs (128 bytes), then 6 u16 indices.
    std::vector<uint8_t> buf;
    append<float>(buf, {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
    append<float>(buf, {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1});
    append<float>(buf, {0, 0, 1, 0, 1, 1, 0, 1});
    append<uint16_t>(buf, {0, 1, 2, 0, 2, 3});
    // One mesh under two nodes, a spot light, a base colour texture with a clamping, nearest sampler and a
    // texture transform, the same image as the metal-rough texture (roughness from G, metalness from B).
    std::ofstream(dir / "s.gltf") << R"({
 "asset": {"version": "2.0"}, "extensionsUsed": ["KHR_texture_transform", "KHR_lights_punctual"],
 "scene": 0, "scenes": [{"nodes": [0, 1, 2]}],
 "nodes": [{"mesh": 0}, {"mesh": 0, "translation": [3, 0, 0], "rotation": [0, 0.7071068, 0, 0.7071068]},
           {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0, 4, 0], "rotation": [-0.7071068, 0, 0, 0.7071068]}],
 "extensions": {"KHR_lights_punctual": {"lights": [{"type": "spot", "color": [1, 0.5, 0.25], "intensity": 20, "range": 9,
                                                     "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.6}}]}},
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]}],
 "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform":
                  {"offset": [0.5, 0.25], "rotation": 0.3, "scale": [2, 3]}}},
                "metallicFactor": 0.25, "roughnessFactor": 0.75, "metallicRoughnessTexture": {"index": 1}},
                "alphaMode": "MASK", "alphaCutoff": 0.4, "doubleSided": true}],
 "textures": [{"source": 0, "sampler": 0}, {"source": 0, "sampler": 1}],
 "samplers": [{"wrapS": 33071, "wrapT": 33648, "magFilter": 9728, "minFilter": 9984}, {}],
 "images": [{"uri": "data:image/png;base64,)" +
                                         base64(png) + R"("}],
 "buffers": [{"byteLength": 140, "uri": "data:application/octet-stream;base64,)" +
                                         base64(buf) + R"("}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 128}, {"buffer": 0, "byteOffset": 128, "byteLength": 12}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
               {"bufferView": 0, "byteOffset": 48, "componentType": 5126, "count": 4, "type": "VEC3"},
               {"bufferView": 0, "byteOffset": 96, "componentType": 5126, "count": 4, "type": "VEC2"},
               {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}]
})";
  }
  void TearDown() override { fs::remove_all(dir); }
  BakeOptions options(const fs::path& output) {
    BakeOptions o{dir / "s.gltf", output};
    o.threads = 1;
    o.warn = o.note = [](const std::string&) {};
    return o;
  }
  std::string bakeError(const fs::path& output) {
    try {
      bake(options(output));
    } catch (const Error& e) { return e.what(); }
    return "(no error)";
  }
};

}  // namespace

TEST_F(BakeGltf, BakedSceneIsTheGltfScene) {
  LoadOptions quiet;
  quiet.warn = quiet.note = [](const std::string&) {};
  const Scene want = loadScene(dir / "s.gltf", quiet);
  // What the test is about is in the loaded scene: one mesh placed twice, a spot light, four textures
  // from the one embedded image (base colour, its alpha as the mask, roughness, metalness), a sampler, a
  // uv transform.
  ASSERT_EQ(want.meshes.size(), 1u);
  ASSERT_EQ(want.instances.size(), 2u);
  ASSERT_EQ(want.lights.size(), 1u);
  EXPECT_EQ(want.lights[0].kind, Light::Kind::Spot);
  ASSERT_EQ(want.textures.size(), 4u);
  for (const Texture& t : want.textures) EXPECT_TRUE(t.bytes && *t.bytes == png);
  EXPECT_EQ(want.textures[0].sampler.wrapU, Wrap::ClampToEdge);
  EXPECT_FALSE(want.materials[0].uv[0].identity());

  const BakeReport r = bake(options(dir / "out" / "s.rtrscene"));
  EXPECT_EQ(r.instances, 2u);
  EXPECT_EQ(r.embeddedTextures, 1u);  // one file for the four textures
  const Scene got = loadScene(dir / "out" / "s.rtrscene");
  test::expectSameScene(want, got, false);
  for (const Texture& t : got.textures) {
    EXPECT_EQ(t.path.parent_path(), "s-tex");
    EXPECT_EQ(t.path.extension(), ".png");
    EXPECT_EQ(readFileBytes(got.baseDir / t.path), png);
  }
  EXPECT_EQ(got.textures[0].path, got.textures[1].path);
  // A second bake beside it finds its image already there, byte for byte, and keeps it.
  fs::rename(dir / "out" / "s.rtrscene", dir / "out" / "s-first.rtrscene");
  EXPECT_EQ(bakeError(dir / "out" / "s.rtrscene"), "(no error)");
}

TEST_F(BakeGltf, ADifferentFileWithTheImagesNameIsNeverOverwritten) {
  const fs::path out = dir / "out";
  ASSERT_EQ(bakeError(out / "s.rtrscene"), "(no error)");
  const Scene baked = loadScene(out / "s.rtrscene");
  const fs::path image = out / baked.textures[0].path;
  fs::remove(out / "s.rtrscene");
  std::ofstream(image, std::ios::binary | std::ios::trunc) << "not that image";
  EXPECT_THAT(bakeError(out / "s.rtrscene"), HasSubstr("a different file has the name of an embedded image"));
  EXPECT_FALSE(fs::exists(out / "s.rtrscene"));
  std::ifstream in(image, std::ios::binary);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "not that image");
  // --force replaces the output and copied textures, still not a file that is not this image.
  BakeOptions o = options(out / "s.rtrscene");
  o.force = true;
  EXPECT_THROW(bake(o), OutputExists);
}

TEST_F(BakeGltf, CourseFormatOutputIsRefusedForGltf) {
  EXPECT_THAT(bakeError(dir / "s.comp5892mesh"), HasSubstr("a glTF bakes to .rtrscene only"));
  EXPECT_FALSE(fs::exists(dir / "s.comp5892mesh"));
}
