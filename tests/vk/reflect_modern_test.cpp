// Reflection of modern SPIR-V: buffer references that form cycles, ray tracing and ray queries, runtime
// descriptor arrays, storage image formats, input attachments, specialization constants, modules with
// several entry points, and modules newer than Debian's spirv-val.
#include <array>
#include <cstdio>
#include <fstream>
#include <filesystem>
#include <memory>

#include <unistd.h>

#include <gtest/gtest.h>

#include "test_paths.hpp"
#include <spirv-tools/libspirv.hpp>

#include "core/error.hpp"
#include "vk/glsl.hpp"
#include "vk/pipeline.hpp"
#include "vk/reflect.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

const std::filesystem::path kData = test::sourceDir() / "tests/vk/data/reflect";

vk::SpirvModule compile(const std::string& name) { return vk::compileGlsl(kData / name); }

const vk::ReflectedBinding& findBinding(const vk::PipelineInterface& p, uint32_t set, uint32_t binding) {
  for (const auto& b : p.bindings)
    if (b.set == set && b.binding == binding) return b;
  throw Error("no set " + std::to_string(set) + " binding " + std::to_string(binding));
}

const vk::BlockMember& member(const std::vector<vk::BlockMember>& ms, const std::string& name) {
  for (const auto& m : ms)
    if (m.name == name) return m;
  throw Error("no member " + name);
}

std::filesystem::path writeModule(const std::string& name, const std::vector<uint32_t>& code) {
  auto dir = std::filesystem::temp_directory_path() / "rtr_reflect_modern_test";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary).write(reinterpret_cast<const char*>(code.data()), code.size() * 4);
  return dir / name;
}

TEST(ReflectModern, SelfReferencingBufferReferencesAreNamedNotExpandedAgain) {
  const vk::PipelineInterface p = vk::reflectPipeline({compile("list.comp")});
  const vk::ReflectedBinding& roots = findBinding(p, 0, 0);
  EXPECT_EQ(roots.blockSize, 52u) << "n at 48 is the last member";
  const vk::BlockMember& head = member(roots.members, "head");
  EXPECT_EQ(head.size, 8u);
  EXPECT_EQ(head.pointee, "Node");
  EXPECT_EQ(head.pointeeSize, 24u) << "vec4 value + Node next";
  ASSERT_EQ(head.members.size(), 2u);
  const vk::BlockMember& next = member(head.members, "next");
  EXPECT_EQ(next.offset, 16u);
  EXPECT_EQ(next.size, 8u);
  EXPECT_EQ(next.pointee, "Node");
  EXPECT_EQ(next.pointeeSize, 24u);
  EXPECT_TRUE(next.members.empty()) << "Node is already listed above";
  const vk::BlockMember& heads = member(roots.members, "heads");
  EXPECT_EQ(heads.offset, 8u);
  EXPECT_EQ(heads.size, 32u) << "four references";
  EXPECT_EQ(heads.pointee, "Node");
  const vk::BlockMember& tail = member(roots.members, "tail");
  EXPECT_EQ(tail.pointee, "Tail");
  EXPECT_EQ(tail.pointeeSize, 4u) << "uint count, then a runtime array";
  ASSERT_EQ(p.pushConstants.size(), 1u);
  EXPECT_EQ(p.pushConstants[0].size, 24u) << "uint k, then two references at 8";
  EXPECT_EQ(member(p.pushConstants[0].members, "ring").size, 16u);
  const std::string text = vk::toText(p);
  EXPECT_NE(text.find("+16 next (8 bytes) -> Node (24 bytes, members listed above)"), std::string::npos) << text;
  EXPECT_NE(vk::toJson(p).find("\"name\":\"next\",\"offset\":16,\"size\":8,\"pointee\":\"Node\",\"pointeeSize\":24"),
            std::string::npos);
}

TEST(ReflectModern, RayTracingStagesMerge) {
  const vk::PipelineInterface p = vk::reflectPipeline({compile("raygen.rgen"), compile("hit.rchit"), compile("miss.rmiss")});
  ASSERT_EQ(p.stages.size(), 3u);
  EXPECT_EQ(p.stages[0].stage, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
  EXPECT_EQ(p.stages[1].stage, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
  EXPECT_EQ(p.stages[2].stage, VK_SHADER_STAGE_MISS_BIT_KHR);
  ASSERT_EQ(p.bindings.size(), 5u);
  EXPECT_EQ(findBinding(p, 0, 0).type, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR);
  EXPECT_EQ(findBinding(p, 0, 1).type, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE);
  EXPECT_EQ(findBinding(p, 0, 1).imageFormat, VK_FORMAT_R8G8B8A8_UNORM);
  const vk::ReflectedBinding& camera = findBinding(p, 0, 2);
  EXPECT_EQ(camera.stages, VkShaderStageFlags(VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR));
  EXPECT_EQ(camera.blockSize, 128u);
  EXPECT_EQ(findBinding(p, 0, 3).stages, VkShaderStageFlags(VK_SHADER_STAGE_MISS_BIT_KHR));
  const vk::ReflectedBinding& colors = findBinding(p, 1, 0);
  EXPECT_EQ(colors.type, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  EXPECT_EQ(colors.count, 0u) << "runtime descriptor array";
  EXPECT_NE(vk::toText(p).find("stage closest-hit: hit.rchit"), std::string::npos);
}

TEST(ReflectModern, RayQueryInComputeShader) {
  const vk::PipelineInterface p = vk::reflectPipeline({compile("query.comp")});
  EXPECT_EQ(p.stages[0].localSize, (std::array<uint32_t, 3>{8, 8, 1}));
  EXPECT_EQ(findBinding(p, 0, 0).type, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR);
  EXPECT_EQ(findBinding(p, 0, 1).imageFormat, VK_FORMAT_R32_SFLOAT);
  EXPECT_NE(vk::toText(p).find("set 0 binding 0: acceleration-structure scene"), std::string::npos) << vk::toText(p);
}

TEST(ReflectModern, ImageFormatsRuntimeArraysNestedPushConstantsAndSpecConstants) {
  const vk::PipelineInterface p = vk::reflectPipeline({compile("resources.comp")});
  const std::pair<uint32_t, VkFormat> formats[] = {{0, VK_FORMAT_R8G8B8A8_UNORM},
                                                   {1, VK_FORMAT_R32_UINT},
                                                   {2, VK_FORMAT_R16G16B16A16_SFLOAT},
                                                   {3, VK_FORMAT_R32G32_SFLOAT},
                                                   {4, VK_FORMAT_B10G11R11_UFLOAT_PACK32}};
  for (auto [binding, format] : formats) {
    EXPECT_EQ(findBinding(p, 0, binding).type, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE);
    EXPECT_EQ(findBinding(p, 0, binding).imageFormat, format) << "binding " << binding;
  }
  EXPECT_STREQ(vk::imageFormatName(findBinding(p, 0, 4).imageFormat), "r11f_g11f_b10f");
  EXPECT_EQ(findBinding(p, 1, 0).type, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE);
  EXPECT_EQ(findBinding(p, 1, 0).count, 0u);
  EXPECT_EQ(findBinding(p, 2, 0).count, 4u);

  ASSERT_EQ(p.pushConstants.size(), 1u);
  EXPECT_EQ(p.pushConstants[0].size, 144u);
  const vk::BlockMember& frame = member(p.pushConstants[0].members, "frame");
  EXPECT_EQ(frame.offset, 16u);
  EXPECT_EQ(frame.size, 128u);
  const vk::BlockMember& lights = member(frame.members, "lights");
  EXPECT_EQ(lights.offset, 64u);
  EXPECT_EQ(member(lights.members, "color").offset, 16u);

  const auto& st = p.stages[0];
  EXPECT_EQ(st.localSize, (std::array<uint32_t, 3>{vk::kSpecializedSize, 4, 1}));
  ASSERT_EQ(st.specConstants.size(), 4u) << "ids 0 (local_size_x_id) to 3, each once";
  EXPECT_EQ(st.specConstants[1].name, "kUseSky");
  EXPECT_EQ(st.specConstants[1].defaultValue, "true");
  EXPECT_EQ(st.specConstants[2].type, "int32");
  EXPECT_EQ(st.specConstants[2].defaultValue, "-3");
  EXPECT_EQ(st.specConstants[3].id, 3u);
  EXPECT_EQ(st.specConstants[3].defaultValue, "0.5");
}

TEST(ReflectModern, InputAttachments) {
  const vk::PipelineInterface p = vk::reflectPipeline({compile("subpass.frag")});
  EXPECT_EQ(findBinding(p, 0, 0).type, VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT);
  EXPECT_EQ(findBinding(p, 0, 0).inputAttachmentIndex, 0u);
  EXPECT_EQ(findBinding(p, 0, 1).inputAttachmentIndex, 2u);
}

TEST(ReflectModern, EachEntryPointOfAModuleIsAStageWithItsOwnResources) {
  std::ifstream in(kData / "two_entry_points.spvasm");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  vk::SpirvModule m{"two_entry_points.spv", {}};
  ASSERT_TRUE(spvtools::SpirvTools(SPV_ENV_VULKAN_1_3).Assemble(text, &m.code));
  const vk::PipelineInterface p = vk::reflectPipeline({m});
  ASSERT_EQ(p.stages.size(), 2u);
  EXPECT_EQ(p.stages[0].entryPoint, "vsMain");
  EXPECT_EQ(p.stages[0].stage, VK_SHADER_STAGE_VERTEX_BIT);
  EXPECT_EQ(p.stages[0].inputs.size(), 1u);
  EXPECT_EQ(p.stages[1].entryPoint, "fsMain");
  EXPECT_EQ(p.stages[1].stage, VK_SHADER_STAGE_FRAGMENT_BIT);
  EXPECT_EQ(p.stages[1].outputs.size(), 1u);
  ASSERT_EQ(p.bindings.size(), 2u);
  EXPECT_EQ(findBinding(p, 0, 0).stages, VkShaderStageFlags(VK_SHADER_STAGE_VERTEX_BIT));
  EXPECT_EQ(findBinding(p, 0, 1).stages, VkShaderStageFlags(VK_SHADER_STAGE_FRAGMENT_BIT));
  EXPECT_EQ(findBinding(p, 0, 1).blockSize, 32u);
  ASSERT_EQ(p.pushConstants.size(), 1u);
  EXPECT_EQ(p.pushConstants[0].stages, VkShaderStageFlags(VK_SHADER_STAGE_FRAGMENT_BIT));
}

vk::SpirvModule assemble(const std::string& file) {
  std::ifstream in(kData / file);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  vk::SpirvModule m{file, {}};
  if (!spvtools::SpirvTools(SPV_ENV_VULKAN_1_3).Assemble(text, &m.code)) throw Error(file + ": does not assemble");
  return m;
}

// A ray-tracing pipeline may hold several shaders of one stage (its groups pick them): not a conflict.
TEST(ReflectModern, RayTracingLibraryWithTwoShadersOfAStage) {
  const vk::PipelineInterface p = vk::reflectPipeline({assemble("rt_library.spvasm")});
  ASSERT_EQ(p.stages.size(), 4u);
  const std::pair<const char*, VkShaderStageFlagBits> want[] = {{"rgenA", VK_SHADER_STAGE_RAYGEN_BIT_KHR},
                                                                {"rgenB", VK_SHADER_STAGE_RAYGEN_BIT_KHR},
                                                                {"ahitA", VK_SHADER_STAGE_ANY_HIT_BIT_KHR},
                                                                {"ahitB", VK_SHADER_STAGE_ANY_HIT_BIT_KHR}};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(p.stages[i].entryPoint, want[i].first);
    EXPECT_EQ(p.stages[i].stage, want[i].second);
  }
  EXPECT_EQ(findBinding(p, 0, 0).stages, VkShaderStageFlags(VK_SHADER_STAGE_RAYGEN_BIT_KHR));
  EXPECT_EQ(findBinding(p, 0, 1).stages, VkShaderStageFlags(VK_SHADER_STAGE_ANY_HIT_BIT_KHR));
  // Two shaders of one graphics stage still are one too many.
  EXPECT_THROW(vk::reflectPipeline({compile("raygen.rgen"), compile("query.comp"), compile("query.comp")}), Error);
}

TEST(ReflectModernTool, RayTracingLibraryPrintsAndExitsZero) {
  const vk::SpirvModule m = assemble("rt_library.spvasm");
  const auto file = std::filesystem::temp_directory_path() / ("rtr_rt_library_" + std::to_string(getpid()) + ".spv");
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(m.code.data()), std::streamsize(m.code.size() * 4));
  int status = -1;
  const std::string out = test::runTool("rtr-reflect", file.string(), &status);
  std::filesystem::remove(file);
  EXPECT_EQ(status, 0) << out;
  EXPECT_NE(out.find("rgenB"), std::string::npos) << out;
  EXPECT_NE(out.find("ahitB"), std::string::npos) << out;
}

using test::VulkanTest;

// The renderer pairs module i with stage i; a module with two entry points is refused, not mismatched.
TEST_F(VulkanTest, GraphicsPipelineRefusesAModuleWithTwoEntryPoints) {
  std::ifstream in(kData / "two_entry_points.spvasm");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  vk::GraphicsDesc d;
  d.modules.push_back({"two_entry_points.spv", {}});
  ASSERT_TRUE(spvtools::SpirvTools(SPV_ENV_VULKAN_1_3).Assemble(text, &d.modules[0].code));
  d.colorFormats = {VK_FORMAT_R8G8B8A8_UNORM};
  EXPECT_THROW(vk::makeGraphicsPipeline(*ctx, d), Error);
}

// A module cut inside an instruction is an error naming the place (SPIRV-Reflect itself aborts on it).
TEST(ReflectModern, ModuleCutInsideAnInstructionIsAnError) {
  vk::SpirvModule m = compile("list.comp");
  m.name = "<memory>";
  EXPECT_EQ(vk::reflectSpirvBytes(m.code.data(), m.code.size() * 4), vk::toText(vk::reflectPipeline({m})));
  std::vector<bool> boundary(m.code.size() + 1, false);
  for (size_t i = 5; i < m.code.size(); i += m.code[i] >> 16) boundary[i] = true;
  int cuts = 0;
  for (size_t words = 6; words < m.code.size(); ++words) {
    if (boundary[words]) continue;
    ++cuts;
    try {
      vk::reflectSpirvBytes(m.code.data(), words * 4, true);
      ADD_FAILURE() << "a module cut at word " << words << " was reflected";
    } catch (const Error& e) { EXPECT_NE(std::string(e.what()).find("<memory>: word "), std::string::npos) << e.what(); }
  }
  EXPECT_GT(cuts, 100);
  EXPECT_THROW(vk::reflectSpirvBytes("abc", 3), Error);
}

// The tool, end to end. These also run against an older rtr-reflect, which fails them.

TEST(ReflectModernTool, LinkedListPrintsAndExitsZero) {
  int status = -1;
  std::string out = test::runTool("rtr-reflect", (kData / "list.comp").string(), &status);
  EXPECT_EQ(status, 0) << out;
  EXPECT_NE(out.find("set 0 binding 0: storage-buffer roots (compute) 52 bytes"), std::string::npos) << out;
  EXPECT_NE(out.find("+16 next (8 bytes) -> Node"), std::string::npos) << out;
}

TEST(ReflectModernTool, ModuleNewerThanSpirvValIsAWarningUnlessStrict) {
  // Slang's source language (11) and a capability (CooperativeMatrixKHR, 6022) that SPIRV-Tools 2023.1
  // does not know; SPIRV-Reflect reads both modules.
  const vk::SpirvModule m = compile("query.comp");
  std::vector<uint32_t> slang = m.code;
  for (size_t i = 5; i < slang.size() && (slang[i] >> 16) > 0; i += slang[i] >> 16)
    if ((slang[i] & 0xffff) == 3 /* OpSource */) {
      slang[i + 1] = 11;
      break;
    }
  std::vector<uint32_t> capability = m.code;
  capability.insert(capability.begin() + 5, {(2u << 16) | 17 /* OpCapability */, 6022});
  for (auto [name, code] : {std::pair{"slang.spv", slang}, {"capability.spv", capability}}) {
    const std::string file = writeModule(name, code).string();
    EXPECT_THROW(vk::validateSpirv({name, code}), Error) << name << ": spirv-val accepts it, so the test proves nothing";
    int status = -1;
    std::string out = test::runTool("rtr-reflect", file, &status);
    EXPECT_EQ(status, 0) << out;
    EXPECT_NE(out.find("warning: " + std::string(name)), std::string::npos) << out;
    EXPECT_NE(out.find("acceleration-structure scene"), std::string::npos) << out;
    out = test::runTool("rtr-reflect", "--strict " + file, &status);
    EXPECT_NE(status, 0) << out;
    EXPECT_NE(out.find(name), std::string::npos) << out;
  }
}

TEST(ReflectModernTool, ModuleSpirvReflectRefusesIsAnErrorNamingTheFile) {
  // A header and nothing else: well formed as far as words go, but no module.
  const std::string file = writeModule("broken.spv", {0x07230203u, 0x00010600u, 0, 64, 0}).string();
  int status = 0;
  std::string out = test::runTool("rtr-reflect", file, &status);
  EXPECT_NE(status, 0);
  EXPECT_NE(out.find("rtr-reflect: error: broken.spv: SPIRV-Reflect cannot read"), std::string::npos) << out;
}

TEST(ReflectModernTool, EachIncludeOptionTakesOneFolder) {
  const std::string data = test::sourceDir().string() + "/tests/vk/data/";
  int status = -1;
  std::string out = test::runTool(
      "rtr-reflect", "-I " + data + " -I " + kData.string() + " " + data + "push_a.vert " + data + "push_ok.frag", &status);
  EXPECT_EQ(status, 0) << out;
  EXPECT_NE(out.find("stage vertex: push_a.vert"), std::string::npos) << out;
  EXPECT_NE(out.find("stage fragment: push_ok.frag"), std::string::npos) << out;
}

}  // namespace
}  // namespace rtr
