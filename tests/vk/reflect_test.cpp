#include "vk/reflect.hpp"

#include <fstream>

#include <gtest/gtest.h>

#include "test_paths.hpp"

#include "core/error.hpp"
#include "vk/glsl.hpp"
#include "vk/pipeline.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

const std::filesystem::path kData = test::sourceDir() / "tests/vk/data";
const std::vector<std::filesystem::path> kIncludes = {test::sourceDir() / "shaders", test::sourceDir() / "shaders/shared"};

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) { return e.what(); }
  return "";
}

// Every item gets a thread and no workgroup is wholly idle: ceil(n / size) per dimension, size reflected.
TEST(Reflect, GroupCountCoversEveryItemWithTheReflectedSize) {
  const vk::PipelineInterface fill = vk::reflectPipeline({vk::loadShader("fill.comp")});  // 64 x 1 x 1
  const auto groups = [&](uint32_t x, uint32_t y = 1) {
    const VkExtent3D g = vk::groupCount(fill, x, y);
    return std::array<uint32_t, 3>{g.width, g.height, g.depth};
  };
  EXPECT_EQ(groups(0), (std::array<uint32_t, 3>{0, 1, 1}));
  EXPECT_EQ(groups(1), (std::array<uint32_t, 3>{1, 1, 1}));
  EXPECT_EQ(groups(64), (std::array<uint32_t, 3>{1, 1, 1}));
  EXPECT_EQ(groups(65), (std::array<uint32_t, 3>{2, 1, 1}));
  EXPECT_EQ(groups(1000, 3), (std::array<uint32_t, 3>{16, 3, 1}));
  EXPECT_EQ(groups(UINT32_MAX), (std::array<uint32_t, 3>{(UINT32_MAX >> 6) + 1, 1, 1})) << "no overflow";
  const vk::PipelineInterface graphics = vk::reflectPipeline({vk::loadShader("mosaic.vert"), vk::loadShader("mosaic.frag")});
  EXPECT_NE(errorOf([&] { vk::groupCount(graphics, 1); }).find("not a compute pipeline"), std::string::npos);
}

TEST(Reflect, FillShaderLayout) {
  vk::PipelineInterface p = vk::reflectPipeline({vk::loadShader("fill.comp")});
  ASSERT_EQ(p.stages.size(), 1u);
  EXPECT_EQ(p.stages[0].stage, VK_SHADER_STAGE_COMPUTE_BIT);
  EXPECT_EQ(p.stages[0].entryPoint, "main");
  EXPECT_EQ(p.stages[0].localSize, (std::array<uint32_t, 3>{64, 1, 1}));
  ASSERT_EQ(p.bindings.size(), 1u);
  EXPECT_EQ(p.bindings[0].set, 0u);
  EXPECT_EQ(p.bindings[0].binding, 0u);
  EXPECT_EQ(p.bindings[0].type, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  EXPECT_EQ(p.bindings[0].stages, VkShaderStageFlags(VK_SHADER_STAGE_COMPUTE_BIT));
  ASSERT_EQ(p.pushConstants.size(), 1u);
  EXPECT_EQ(p.pushConstants[0].offset, 0u);
  EXPECT_EQ(p.pushConstants[0].size, 8u);
  ASSERT_EQ(p.pushConstants[0].members.size(), 2u);
  EXPECT_EQ(p.pushConstants[0].members[1].name, "offset");
  EXPECT_EQ(p.pushConstants[0].members[1].offset, 4u);
}

TEST(Reflect, StagesMergeAndVertexInputsAreReflected) {
  vk::PipelineInterface p = vk::reflectPipeline(
      {vk::compileGlsl(kData / "push_a.vert", kIncludes), vk::compileGlsl(kData / "push_ok.frag", kIncludes)});
  ASSERT_EQ(p.stages.size(), 2u);
  ASSERT_EQ(p.stages[0].inputs.size(), 2u);
  EXPECT_EQ(p.stages[0].inputs[0].format, VK_FORMAT_R32G32B32_SFLOAT);
  EXPECT_EQ(p.stages[0].inputs[1].format, VK_FORMAT_R32G32_SFLOAT);
  ASSERT_EQ(p.bindings.size(), 1u);
  EXPECT_EQ(p.bindings[0].set, 1u);
  EXPECT_EQ(p.bindings[0].count, 0u) << "runtime-sized array";
  EXPECT_EQ(p.bindings[0].type, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER);
  ASSERT_EQ(p.pushConstants.size(), 1u);
  EXPECT_EQ(p.pushConstants[0].offset, 0u);
  EXPECT_EQ(p.pushConstants[0].size, 80u);
  EXPECT_EQ(p.pushConstants[0].stages, VkShaderStageFlags(VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT));
}

TEST(Reflect, DescriptorConflictNamesShadersSetAndBinding) {
  std::string msg = errorOf([] {
    vk::reflectPipeline({vk::compileGlsl(kData / "conflict.vert"), vk::compileGlsl(kData / "conflict.frag")});
  });
  EXPECT_NE(msg.find("set 0 binding 1"), std::string::npos) << msg;
  EXPECT_NE(msg.find("conflict.vert"), std::string::npos) << msg;
  EXPECT_NE(msg.find("conflict.frag"), std::string::npos) << msg;
}

TEST(Reflect, PushConstantConflictIsAnError) {
  std::string msg = errorOf([] {
    vk::reflectPipeline({vk::compileGlsl(kData / "push_a.vert"), vk::compileGlsl(kData / "push_b.frag")});
  });
  EXPECT_NE(msg.find("push constants"), std::string::npos) << msg;
  EXPECT_NE(msg.find("push_b.frag"), std::string::npos) << msg;
}

TEST(Reflect, InvalidSpirvIsRejected) {
  auto dir = std::filesystem::temp_directory_path() / "rtr_reflect_test";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "garbage.spv", std::ios::binary) << "this is not a SPIR-V module!";  // 28 bytes
  EXPECT_NE(errorOf([&] { vk::readSpirv(dir / "garbage.spv"); }).find("magic"), std::string::npos);
  std::ofstream(dir / "odd.spv", std::ios::binary) << "abc";
  EXPECT_NE(errorOf([&] { vk::readSpirv(dir / "odd.spv"); }).find("multiple of 4"), std::string::npos);
  // A real module cut in half: the reflector or the validator must refuse it, not crash.
  vk::SpirvModule m = vk::loadShader("fill.comp");
  m.code.resize(m.code.size() / 2);
  EXPECT_FALSE(errorOf([&] { vk::validateSpirv(m); }).empty());
  EXPECT_FALSE(errorOf([&] { vk::reflectPipeline({m}); }).empty());
  std::filesystem::remove_all(dir);
}

TEST(Reflect, GlslCompileErrorNamesFileAndLine) {
  auto dir = std::filesystem::temp_directory_path() / "rtr_glsl_test";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "bad.comp") << "#version 460\nlayout(local_size_x = 1) in;\nvoid main() { undefined_thing = 1; }\n";
  std::string msg = errorOf([&] { vk::compileGlsl(dir / "bad.comp"); });
  EXPECT_NE(msg.find("bad.comp:3"), std::string::npos) << msg;
  std::filesystem::remove_all(dir);
}

using test::VulkanTest;

// The layout a pipeline is built with is the reflected interface itself (same code path as rtr-reflect).
TEST_F(VulkanTest, RuntimeArrayNeedsACountAndThenBuilds) {
  auto iface = vk::reflectPipeline({vk::compileGlsl(kData / "push_a.vert"), vk::compileGlsl(kData / "push_ok.frag")});
  EXPECT_THROW(vk::PipelineLayout(*ctx, iface), Error);
  vk::LayoutOptions o;
  o.runtimeArrayCounts[{1, 0}] = 5;
  vk::PipelineLayout layout(*ctx, iface, o);
  EXPECT_EQ(layout.setCount(), 2u);
  EXPECT_EQ(layout.arrayCount(layout.binding(1, 0)), 5u);
}

}  // namespace
}  // namespace rtr
