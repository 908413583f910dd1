// rtr-reflect prints exactly the interface the renderer builds its pipeline layouts from.
#include <sys/wait.h>

#include <array>
#include <filesystem>
#include <cstdio>
#include <memory>

#include <gtest/gtest.h>

#include "test_paths.hpp"

#include "render/renderer.hpp"
#include "vk/pipeline.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using test::VulkanTest;

TEST_F(VulkanTest, ReflectToolMatchesTheRenderersPipelines) {
  const std::string dir = vk::shaderDir().string() + "/";
  for (auto [vert, frag] : {std::pair{"scene.vert", "pbr.frag"}, {"scene_untextured.vert", "pbr_untextured.frag"},
                            {"scene.vert", "pbr_alpha.frag"}, {"scene.vert", "debug.frag"}}) {
    vk::GraphicsDesc d;
    d.modules = {vk::loadShader(vert), vk::loadShader(frag)};
    d.colorFormats = {render::Renderer::kColorFormat};
    d.depthFormat = render::Renderer::kDepthFormat;
    vk::LayoutOptions o;
    o.runtimeArrayCounts[{1, 0}] = 3;
    vk::Pipeline p = vk::makeGraphicsPipeline(*ctx, d, o);
    int status = -1;
    std::string json = test::runTool("rtr-reflect", "--json " + dir + vert + ".spv " + dir + frag + ".spv", &status);
    EXPECT_EQ(status, 0) << json;
    EXPECT_EQ(json, vk::toJson(p.layout.interface())) << vert << " + " << frag;
  }
}

TEST(ReflectTool, ConflictAndBadInputExitNonZero) {
  int status = 0;
  const std::string data = test::sourceDir().string() + "/tests/vk/data/";
  std::string out = test::runTool("rtr-reflect", data + "conflict.vert " + data + "conflict.frag", &status);
  EXPECT_NE(status, 0);
  EXPECT_NE(out.find("set 0 binding 1"), std::string::npos) << out;
  out = test::runTool("rtr-reflect", test::sourceDir().string() + "/README.md", &status);
  EXPECT_NE(status, 0);
  EXPECT_NE(out.find("not SPIR-V"), std::string::npos) << out;
}

// Modules that make SPIRV-Reflect assert or crash (found by fuzzing, most of them valid for spirv-val): the
// tool reports each, naming the file, and exits 1; it never dies of a signal.
TEST(ReflectTool, ModulesThatCrashSpirvReflectAreErrors) {
  const auto dir = test::sourceDir() / "tests/fuzz/crashes/fuzz_spirv";
  int seen = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    int status = 0;
    const std::string out = test::runTool("rtr-reflect", e.path().string(), &status);
    ASSERT_TRUE(WIFEXITED(status)) << e.path() << "\n" << out;
    EXPECT_EQ(WEXITSTATUS(status), 1) << e.path() << "\n" << out;
    EXPECT_NE(out.find("rtr-reflect: error: "), std::string::npos) << out;
    EXPECT_NE(out.find(e.path().filename().string()), std::string::npos) << out;
    ++seen;
  }
  EXPECT_GE(seen, 4);
}

}  // namespace
}  // namespace rtr
