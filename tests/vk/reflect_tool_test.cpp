// rtr-reflect prints exactly the interface the renderer builds its pipeline layouts from.
#include <sys/wait.h>

#include <array>
#include <filesystem>
#include <cstdio>
#include <memory>

#include <gtest/gtest.h>

#include "test_paths.hpp"

#include "render/renderer.hpp"
#include "variants.h"
#include "vk/pipeline.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

using test::VulkanTest;

// Each variant of the renderer's (specialization constants, variants.h): rtr-reflect --spec gives it too.
struct Variant {
  const char *vert, *frag;
  std::vector<vk::SpecializationConstant> spec;
};
const Variant kVariants[] = {{"scene.vert", "pbr.frag", {{VARIANT_TEXCOORDS, 1}, {VARIANT_ALPHA_MASK, 0}}},
                             {"scene.vert", "pbr.frag", {{VARIANT_TEXCOORDS, 0}, {VARIANT_ALPHA_MASK, 0}}},
                             {"scene.vert", "pbr.frag", {{VARIANT_TEXCOORDS, 1}, {VARIANT_ALPHA_MASK, 1}}},
                             {"scene.vert", "debug.frag", {{VARIANT_TEXCOORDS, 0}}},
                             {"vis.vert", "vis.frag", {{VARIANT_ALPHA_MASK, 1}}},
                             {"vis.vert", "vis.frag", {}}};

TEST_F(VulkanTest, ReflectToolMatchesTheRenderersPipelines) {
  const std::string dir = vk::shaderDir().string() + "/";
  for (const Variant& v : kVariants) {
    vk::GraphicsDesc d;
    d.modules = {vk::loadShader(v.vert), vk::loadShader(v.frag)};
    d.colorFormats = {std::string(v.vert) == "vis.vert" ? render::Renderer::kVisFormat : render::Renderer::kColorFormat};
    d.depthFormat = render::Renderer::kDepthFormat;
    d.specialization = v.spec;
    vk::LayoutOptions o;
    o.runtimeArrayCounts[{1, 0}] = 3;
    vk::Pipeline p = vk::makeGraphicsPipeline(*ctx, d, o);
    std::string args = "--json";
    for (const auto& c : v.spec) args += " --spec " + std::to_string(c.id) + "=" + std::to_string(c.value);
    int status = -1;
    std::string json = test::runTool("rtr-reflect", args + " " + dir + v.vert + ".spv " + dir + v.frag + ".spv", &status);
    EXPECT_EQ(status, 0) << json;
    EXPECT_EQ(json, vk::toJson(p.layout.interface())) << v.vert << " + " << v.frag << " " << args;
  }
}

bool hasBinding(const vk::PipelineInterface& p, uint32_t set, uint32_t binding) {
  for (const auto& b : p.bindings)
    if (b.set == set && b.binding == binding) return true;
  return false;
}

// One source per pass: a variant keeps only the inputs and descriptors its branches use, so an untextured
// scene binds no texcoord stream and no texture set, and the id buffer or image is the one the path has.
TEST(Specialization, EachVariantHasOnlyTheInterfaceItUses) {
  auto reflect = [](std::vector<const char*> names, const std::vector<vk::SpecializationConstant>& spec) {
    std::vector<vk::SpirvModule> modules;
    for (const char* n : names) modules.push_back(vk::specialize(vk::loadShader(n), spec));
    return vk::reflectPipeline(modules);
  };
  for (uint32_t textured : {0u, 1u}) {
    SCOPED_TRACE(textured ? "textured" : "untextured");
    const vk::PipelineInterface forward = reflect({"scene.vert", "pbr.frag"}, {{VARIANT_TEXCOORDS, textured}});
    EXPECT_EQ(forward.stages[0].inputs.size(), textured ? 3u : 2u);  // positions, normals (, texcoords)
    EXPECT_EQ(hasBinding(forward, 1, 0), bool(textured));
    for (uint32_t buffer : {0u, 1u}) {
      const vk::PipelineInterface shade =
          reflect({"vis_shade.comp"}, {{VARIANT_TEXCOORDS, textured}, {VARIANT_VIS_BUFFER, buffer}});
      EXPECT_EQ(hasBinding(shade, 1, 0), bool(textured));
      EXPECT_EQ(hasBinding(shade, 0, 9), bool(textured));  // texcoords
      EXPECT_EQ(hasBinding(shade, 0, 7), !buffer);         // the id image
      EXPECT_EQ(hasBinding(shade, 0, 14), bool(buffer));   // the compute rasteriser's buffer
    }
    // glTF's streams (second uv set, tangents, vertex colours) only in the MATERIAL_EXTRAS variant.
    for (uint32_t extras : {0u, 1u}) {
      const vk::PipelineInterface shade =
          reflect({"vis_shade.comp"}, {{VARIANT_TEXCOORDS, textured}, {VARIANT_MATERIAL_EXTRAS, extras}});
      EXPECT_EQ(hasBinding(shade, 0, 11), textured && extras);
      EXPECT_EQ(hasBinding(shade, 0, 12), textured && extras);
      EXPECT_EQ(hasBinding(shade, 0, 13), bool(extras));
    }
  }
  for (uint32_t alpha : {0u, 1u}) {
    const vk::PipelineInterface vis = reflect({"vis.vert", "vis.frag"}, {{VARIANT_ALPHA_MASK, alpha}});
    EXPECT_EQ(vis.stages[0].inputs.size(), alpha ? 2u : 1u);  // positions (, texcoords)
    EXPECT_EQ(hasBinding(vis, 1, 0), bool(alpha));
  }
  // No constants: the module as compiled. The same constants: the same module, so the driver's pipeline
  // cache (keyed on the module's code) hits on the next start.
  const vk::SpirvModule pbr = vk::loadShader("pbr.frag");
  EXPECT_EQ(vk::specialize(pbr, {}).code, pbr.code);
  EXPECT_EQ(vk::specialize(pbr, {{VARIANT_TEXCOORDS, 0}}).code, vk::specialize(pbr, {{VARIANT_TEXCOORDS, 0}}).code);
  EXPECT_NE(vk::specialize(pbr, {{VARIANT_TEXCOORDS, 0}}).code, vk::specialize(pbr, {{VARIANT_TEXCOORDS, 1}}).code);
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
