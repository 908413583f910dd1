// GPU-vs-CPU reference tests: every case of poses.txt rendered by the Vulkan renderer (lavapipe) and by
// the CPU ray tracer, in three views (PBR shaded, |normal|, linear depth), compared edge-tolerantly.
// Images, error maps and the numbers go to <build>/reference-out/ (docs/reference-tests.md).
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>

#include <gtest/gtest.h>

#include "test_paths.hpp"

#include "core/compare.hpp"
#include "reference_common.hpp"
#include "vk_fixture.hpp"

namespace rtr::reftest {
namespace {

const char* const kCases[] = {"temple_nave",
                              "temple_aisle",
                              "cornell_box",
                              "cube_backplane",
                              "grazing_floor",
                              "metal_sphere",
                              "rough0_patch",
                              "backface_quad",
                              "temple_nave_textured",
                              "temple_aisle_textured",
                              "cube_backplane_falloff",
                              "two_lights",
                              "two_lights_falloff",
                              "headlight",
                              "gltf_metal_rough",
                              "gltf_emissive",
                              "gltf_spot",
                              "gltf_alpha_mask",
                              "gltf_blend",
                              "gltf_normal_map",
                              "gltf_texture_transform"};

// The shaded view runs once per visibility rasteriser (the debug views are forward: no ids).
struct Param {
  std::string name;
  View view;
  render::RasterPath raster = render::RasterPath::Auto;
  std::string label() const {
    return name + "_" + viewName(view) + (raster == render::RasterPath::Auto ? "" : std::string("_") + rtr::enumName(raster));
  }
};

std::vector<Param> allParams() {
  std::vector<Param> out;
  for (const char* c : kCases) {
    for (auto r : {render::RasterPath::Hardware, render::RasterPath::Compute}) out.push_back({c, View::Shaded, r});
    for (View v : {View::Normals, View::Depth}) out.push_back({c, v});
  }
  return out;
}

class ReferenceTest : public test::VulkanTest, public ::testing::WithParamInterface<Param> {};

TEST_P(ReferenceTest, GpuMatchesCpu) {
  const Param& p = GetParam();
  if (p.name == "gltf_normal_map" && p.view == View::Normals)
    GTEST_SKIP() << "the normals views disagree on a normal-mapped surface: the GPU's mode 5 shows the mapped "
                    "normal, the tracer's normals view the interpolated one (the shaded views agree)";
  if (p.name == "gltf_blend" && p.view != View::Shaded)
    GTEST_SKIP() << "the GPU's debug views show opaque surfaces only (no transparency pass), the tracer's the first "
                    "surface hit, blended or not";
  const auto poses = loadPoses(posesFile());
  ASSERT_TRUE(poses.count(p.name)) << p.name << " has no pose in " << posesFile();
  const ReferenceScene rs = makeScene(p.name, outDir() / "work");
  PairOptions options;
  options.raster = p.raster;
  const CasePair pair = renderPair(*ctx, rs, poses.at(p.name), p.view, options);
  const std::string id = p.label();

  // Not blank: a comparison of two black images proves nothing.
  EXPECT_EQ(blankReason(pair.gpu), "") << id + " GPU";
  EXPECT_EQ(blankReason(pair.cpu), "") << id + " CPU";
  // The displayed bytes (post pass, mosaic off) are the intermediate image sRGB-encoded: the conversion
  // used below for the GPU side is the one a viewer shows.
  const CompareResult post = compareEdgeTolerant(pair.gpuDisplayed, pair.gpu, 1);
  EXPECT_EQ(post.failingPixels, 0u) << id << ": post pass output differs from toSrgb8(scene colour) by > 1";

  const Limits lim = limits(p.name, p.view);
  const CompareResult r = compareEdgeTolerant(pair.gpu, pair.cpu, lim.threshold);
  writeOutputs(id, pair, r, lim);
  EXPECT_LE(r.failingFraction, lim.maxFailingFraction)
      << id << ": " << r.failingPixels << " pixels differ by more than " << lim.threshold << " (see "
      << (outDir() / (id + "_err.png")).string() << ")";
}

INSTANTIATE_TEST_SUITE_P(Cases, ReferenceTest, ::testing::ValuesIn(allParams()),
                         [](const ::testing::TestParamInfo<Param>& i) { return i.param.label(); });

// Every case in poses.txt is run (the environment cases by rtr-frame-compare --env-cases, which takes
// every env_* case, and env_reference_test), every run case has a pose, and each has its comment.
TEST(ReferencePoses, FileAndCasesAgree) {
  const auto poses = loadPoses(posesFile());
  std::set<std::string> run(std::begin(kCases), std::end(kCases));
  for (const auto& [name, e] : poses) {
    EXPECT_TRUE(run.count(name) || isEnvironmentCase(name)) << name << " is in poses.txt but no test runs it";
    EXPECT_FALSE(e.comment.empty()) << name;
  }
  for (const std::string& name : run) EXPECT_TRUE(poses.count(name)) << name << " has no pose";
  EXPECT_TRUE(poses.count("env_sphere_grid")) << "env_reference_test's case";
}

// The untextured temple copy removes exactly the card meshes and keeps no texture reference.
TEST(ReferenceScenes, UntexturedTempleDropsOnlyCards) {
  const Scene temple = loadScene(test::assetDir() / "temple.rtrscene");
  int removed = 0;
  const Scene s = untexturedTemple(temple, &removed);
  EXPECT_EQ(removed, 4) << "foliage, ivy, fire_L, fire_R expected; the generated scene changed?";
  EXPECT_TRUE(s.textures.empty());
  for (const Material& m : s.materials)
    for (uint32_t t : m.textures) EXPECT_EQ(t, kNoTexture) << m.name;
  EXPECT_GT(s.meshes.size(), 10u);
}

// The baked temple carries the brief's light (rtr-bake --light at build time), and both renderers use it.
TEST(ReferenceScenes, TempleIsLitByTheBriefsStoredLight) {
  for (const char* name : {"temple_nave", "temple_nave_textured"}) {
    const ReferenceScene rs = makeScene(name, outDir() / "work");
    ASSERT_EQ(rs.lights.lights.size(), 1u) << name;
    EXPECT_EQ(rs.lights.lights[0].kind, Light::Kind::Point) << name;
    EXPECT_EQ(rs.lights.lights[0].position, briefLight().position) << name;
    EXPECT_TRUE(rs.lights.note.empty()) << rs.lights.note;
  }
}

// The textured temple is the scene as baked (textures, cards), with only the fire cards made two-sided.
TEST(ReferenceScenes, TexturedTempleKeepsTexturesAndCards) {
  const Scene temple = loadScene(test::assetDir() / "temple.rtrscene");
  const Scene s = texturedTemple(temple, outDir() / "work");
  EXPECT_EQ(s.meshes.size(), temple.meshes.size());
  EXPECT_EQ(s.textures.size(), temple.textures.size() + 1);  // the opaque mask of the fire cards
  int fire = 0;
  for (const Mesh& m : s.meshes)
    if (m.name.rfind("fire_", 0) == 0) {
      ++fire;
      EXPECT_TRUE(s.materials[m.material].flags & kMaterialDoubleSided) << m.name;
    }
  EXPECT_EQ(fire, 2);
}

}  // namespace
}  // namespace rtr::reftest
