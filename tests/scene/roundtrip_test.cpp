// Both baked formats round-trip through the loader to the meshes and materials that were baked.
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "bake.hpp"
#include "core/error.hpp"
#include "core/mip_reference.hpp"
#include "scene/baked_texels.hpp"
#include "scene/course.hpp"
#include "scene/textures.hpp"
#include "scene/load.hpp"
#include "scene/rtrscene.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using namespace rtr;

namespace {

fs::path tempDir(const char* tag) {
  fs::path d = fs::temp_directory_path() / (std::string("rtr_") + tag + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void expectSameMeshes(const Scene& a, const Scene& b) {
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  for (size_t i = 0; i < a.meshes.size(); ++i) {
    const Mesh &x = a.meshes[i], &y = b.meshes[i];
    EXPECT_EQ(x.material, y.material);
    EXPECT_EQ(x.positions, y.positions);
    EXPECT_EQ(x.normals, y.normals);
    EXPECT_EQ(x.texcoords, y.texcoords);
    EXPECT_EQ(x.indices, y.indices);
    EXPECT_EQ(x.bounds.min, y.bounds.min);
    EXPECT_EQ(x.bounds.max, y.bounds.max);
    ASSERT_EQ(x.clusters.size(), y.clusters.size());  // stored by the baker or built at load: the same
    for (size_t c = 0; c < x.clusters.size(); ++c) {
      EXPECT_EQ(x.clusters[c].firstTriangle, y.clusters[c].firstTriangle);
      EXPECT_EQ(x.clusters[c].triangleCount, y.clusters[c].triangleCount);
      EXPECT_EQ(x.clusters[c].center, y.clusters[c].center);
      EXPECT_EQ(x.clusters[c].coneCutoff, y.clusters[c].coneCutoff);
    }
  }
}

void expectSameTextures(const Scene& a, const Scene& b) {
  ASSERT_EQ(a.textures.size(), b.textures.size());
  for (size_t i = 0; i < a.textures.size(); ++i) {
    EXPECT_EQ(a.textures[i].path, b.textures[i].path);
    EXPECT_EQ(a.textures[i].srgb, b.textures[i].srgb);
    EXPECT_EQ(a.textures[i].channels, b.textures[i].channels);
  }
}

// The temple as the baker sees it: parsed, with paths planned for an output named "temple".
Scene planned(bool course) {
  Scene s = loadScene(rtr::test::sourceDir() / "assets-src/temple/temple.obj.zst");
  s.defaultView = CameraPose{{1, 2, 3}, 45, -10};
  return planTextures(s, "temple", course).scene;
}

}  // namespace

TEST(RoundTrip, RtrSceneKeepsEverything) {
  const Scene want = planned(false);
  const fs::path dir = tempDir("rt_rtrscene");
  BakeOptions o{rtr::test::sourceDir() / "assets-src/temple/temple.obj.zst", dir / "temple.rtrscene"};
  o.view = want.defaultView;
  Light light;
  light.position = {1, 2, 3};
  light.color = {0.5f, 0.25f, 2};
  o.lights = {light};
  o.threads = 2;
  bake(o);
  const Scene got = loadScene(o.output);
  ASSERT_EQ(got.lights.size(), 1u);  // --light is stored with the scene
  EXPECT_EQ(got.lights[0].position, light.position);
  EXPECT_EQ(got.lights[0].color, light.color);
  EXPECT_EQ(got.baseDir, dir);
  expectSameMeshes(want, got);
  for (size_t i = 0; i < want.meshes.size(); ++i) EXPECT_EQ(want.meshes[i].name, got.meshes[i].name);
  expectSameTextures(want, got);
  ASSERT_EQ(want.materials.size(), got.materials.size());
  for (size_t i = 0; i < want.materials.size(); ++i) {
    const Material &a = want.materials[i], &b = got.materials[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.flags, b.flags);
    EXPECT_EQ(a.textures, b.textures);
    EXPECT_EQ(a.baseColor, b.baseColor);
    EXPECT_EQ(a.roughness, b.roughness);
    EXPECT_EQ(a.metalness, b.metalness);
    EXPECT_EQ(a.emissive, b.emissive);
    EXPECT_EQ(a.ka, b.ka);
    EXPECT_EQ(a.kd, b.kd);
    EXPECT_EQ(a.ks, b.ks);
    EXPECT_EQ(a.ke, b.ke);
    EXPECT_EQ(a.ns, b.ns);
    EXPECT_EQ(a.mirror, b.mirror);
    EXPECT_EQ(a.ior, b.ior);
    EXPECT_EQ(a.transparency, b.transparency);
  }
  ASSERT_TRUE(got.defaultView.has_value());
  EXPECT_EQ(got.defaultView->position, want.defaultView->position);
  EXPECT_EQ(got.defaultView->yawDeg, 45.0f);
  EXPECT_EQ(got.defaultView->pitchDeg, -10.0f);
  // Textures were copied beside the output and decode.
  for (const Texture& t : got.textures) EXPECT_TRUE(fs::is_regular_file(got.baseDir / t.path)) << t.path;
  fs::remove_all(dir);
}

TEST(RoundTrip, CourseFormatKeepsMeshesAndTextureSlots) {
  const Scene want = planned(false);  // fallbacks read back as "no texture"
  const fs::path dir = tempDir("rt_course");
  BakeOptions o{rtr::test::sourceDir() / "assets-src/temple/temple.obj.zst", dir / "temple.comp5892mesh"};
  o.threads = 2;
  bake(o);
  const Scene got = loadScene(o.output);
  expectSameMeshes(want, got);
  expectSameTextures(want, got);
  ASSERT_EQ(want.materials.size(), got.materials.size());
  for (size_t i = 0; i < want.materials.size(); ++i) {
    EXPECT_EQ(want.materials[i].textures, got.materials[i].textures) << want.materials[i].name;
    EXPECT_EQ(want.materials[i].flags & kMaterialAlphaMasked, got.materials[i].flags & kMaterialAlphaMasked);
  }
  fs::remove_all(dir);
}

TEST(RoundTrip, SixteenAndThirtyTwoBitIndicesAndMissingAttributes) {
  Scene s;
  s.materials.push_back(Material{.name = "m"});
  Mesh big;
  for (uint32_t i = 0; i < 70000; ++i) big.positions.push_back({float(i), float(i % 3), 0.0f});
  big.normals.assign(big.positions.size(), glm::vec3(0, 0, 1));
  for (uint32_t i = 0; i + 2 < 70000; i += 3) big.indices.insert(big.indices.end(), {i, i + 1, 69999 - i});
  for (auto& p : big.positions) big.bounds.extend(p);
  Mesh small;
  small.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  small.texcoords = {{0, 0}, {1, 0}, {0, 1}};
  small.indices = {0, 1, 2};
  for (auto& p : small.positions) small.bounds.extend(p);
  s.meshes = {big, small, Mesh{}};
  const std::string bytes = encodeRtrScene(s);
  const Scene got = decodeRtrScene({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()}, "mem.rtrscene");
  expectSameMeshes(s, got);
  EXPECT_TRUE(got.meshes[1].normals.empty());
}

// loadRtrScene maps the file instead of reading it: the scene is the one decoded from the same bytes in
// memory; an empty file, a folder and a missing file are refused naming the path.
TEST(RoundTrip, MappedFileLoadsWhatTheBytesDecodeTo) {
  const auto dir = std::filesystem::temp_directory_path() / ("rtr_mapped_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const Scene s = loadScene(test::sourceDir() / "assets-src/rt/cornell_box.obj");
  const std::string bytes = encodeRtrScene(s);
  std::ofstream(dir / "a.rtrscene", std::ios::binary) << bytes;
  const Scene mapped = loadRtrScene(dir / "a.rtrscene");
  const Scene inMemory = decodeRtrScene({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()}, "a.rtrscene");
  expectSameMeshes(inMemory, mapped);
  EXPECT_EQ(mapped.baseDir, dir);
  std::ofstream(dir / "empty.rtrscene");
  std::filesystem::create_directories(dir / "folder.rtrscene");
  for (const char* f : {"empty.rtrscene", "folder.rtrscene", "missing.rtrscene"}) {
    try {
      loadRtrScene(dir / f);
      ADD_FAILURE() << f << " loaded";
    } catch (const Error& e) { EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what(); }
  }
  std::filesystem::remove_all(dir);
}

// --textures lossless: no texture file is written; each texture's chain in the file is its source image
// (level 0, the slot's channel taken) and the reference filter's levels below it, in linear light for sRGB
// colour (core/mip_reference.hpp), laid out as BakedTexels::levelOffsets says.
TEST(RoundTrip, LosslessTexturesAreTheReferenceChainsInTheFile) {
  const Scene want = planned(false);
  const Scene source = loadScene(rtr::test::sourceDir() / "assets-src/temple/temple.obj.zst");
  const fs::path dir = tempDir("rt_lossless");
  BakeOptions o{rtr::test::sourceDir() / "assets-src/temple/temple.obj.zst", dir / "temple.rtrscene"};
  o.textures = TextureStore::Lossless;
  o.threads = 2;
  const BakeReport rep = bake(o);
  EXPECT_FALSE(fs::exists(dir / "temple-tex")) << "no texture file is written";
  EXPECT_GT(rep.texelBytes, rep.storedTexelBytes);
  const Scene got = loadScene(o.output);
  expectSameMeshes(want, got);
  expectSameTextures(want, got);
  ASSERT_EQ(got.textures.size(), source.textures.size());
  bool srgbSeen = false, greySeen = false;
  for (size_t i = 0; i < got.textures.size(); ++i) {
    const Texture& t = got.textures[i];
    ASSERT_TRUE(t.baked) << t.path;
    const BakedTexels& b = *t.baked;
    std::vector<uint8_t> chain(b.bytes());
    for (size_t k = 0; k < b.pieces.size(); ++k) unpackBakedPiece(b, k, chain.data());
    const int channels = t.channels == 1 ? 1 : 4;
    const TexelData level0 = decodeTexture(source, source.textures[i]);
    ASSERT_EQ(int(level0.channels), channels);
    const bool srgb = t.srgb && channels == 4;
    srgbSeen |= srgb;
    greySeen |= channels == 1;
    const MipChain ref = buildMipReference(level0, srgb ? TexelEncoding::Srgb : TexelEncoding::Unorm, MipSource::PreviousLevel);
    const std::vector<uint64_t> at = b.levelOffsets();
    ASSERT_EQ(b.levels(), ref.levels.size());
    for (uint32_t l = 0; l < b.levels(); ++l) {
      const std::vector<uint8_t> expect = l == 0 ? level0.texels : quantizeMipLevel(ref, l);
      EXPECT_TRUE(std::equal(expect.begin(), expect.end(), chain.begin() + ptrdiff_t(at[l]))) << t.path << " level " << l;
    }
  }
  EXPECT_TRUE(srgbSeen && greySeen) << "both kinds of texture are covered";
  fs::remove_all(dir);
}

// --textures bc: each level holds what the encoder makes of the reference chain's level, and the chains are
// the same bytes on any thread count: textures in parallel, and a lone texture's levels in pieces of block
// rows on the cores the textures leave free.
TEST(RoundTrip, BlockCompressedChainsAreTheSameOnAnyThreadCount) {
  const Scene source = loadScene(rtr::test::sourceDir() / "assets-src/temple/temple.obj.zst");
  auto chains = [&](size_t textures, unsigned threads) {
    TexturePlan plan = planTextures(source, "t", false);
    plan.scene.textures.resize(textures), plan.sources.resize(textures), plan.bytes.resize(textures);
    std::vector<LevelError> error;
    bakeTexels(plan, threads, "MTL", {}, true, &error);
    std::vector<std::vector<uint8_t>> out;
    for (const Texture& t : plan.scene.textures) {
      for (size_t k = 0; k < t.baked->pieces.size(); ++k)
        EXPECT_EQ(t.baked->pieces[k].stored, t.baked->pieceBytes(k)) << "blocks are stored as they are, not zstd";
      std::vector<uint8_t> chain(t.baked->bytes());
      for (size_t k = 0; k < t.baked->pieces.size(); ++k) unpackBakedPiece(*t.baked, k, chain.data());
      out.push_back(std::move(chain));
    }
    return out;
  };
  const auto all = chains(source.textures.size(), 1);
  EXPECT_EQ(chains(source.textures.size(), 3), all);
  EXPECT_EQ(chains(source.textures.size(), 0), all);
  for (unsigned threads : {2u, 5u}) EXPECT_EQ(chains(1, threads), std::vector<std::vector<uint8_t>>{all[0]}) << threads;
  // Texture 0's levels, each the encoder's blocks of the reference chain's level.
  const TexelData level0 = decodeTexture(source, source.textures[0]);
  ASSERT_EQ(level0.channels, 4u);
  const std::vector<uint8_t> ref = referenceChain(level0, source.textures[0].srgb);
  BakedTexels lossless, blocks;
  lossless.width = blocks.width = level0.width;
  lossless.height = blocks.height = level0.height;
  bool opaque = true;
  for (size_t k = 3; k < level0.texels.size(); k += 4) opaque &= level0.texels[k] == 255;
  blocks.format = opaque ? BakedFormat::Bc1 : BakedFormat::Bc3;
  const std::vector<uint64_t> from = lossless.levelOffsets(), to = blocks.levelOffsets();
  ASSERT_EQ(all[0].size(), to.back());
  for (uint32_t l = 0; l < blocks.levels(); ++l) {
    const std::vector<uint8_t> want =
        encodeBakedLevel(blocks.format, mipLevelSize(level0.width, l), mipLevelSize(level0.height, l), ref.data() + from[l]);
    EXPECT_TRUE(std::equal(want.begin(), want.end(), all[0].begin() + ptrdiff_t(to[l]))) << "level " << l;
  }
}
