#pragma once
// A pipeline's interface read from its SPIR-V with SPIRV-Reflect: the one source of every descriptor
// set layout and push-constant range in the project (none is written by hand), and what rtr-reflect prints.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

namespace rtr::vk {

struct SpirvModule {
  std::string name;             // file name, for messages
  std::vector<uint32_t> code;
};

// Reads a .spv file; a wrong size or magic number is an rtr::Error naming the file.
SpirvModule readSpirv(const std::filesystem::path& file);
// Runs the SPIRV-Tools validator (Vulkan 1.3 rules); throws rtr::Error with its message.
void validateSpirv(const SpirvModule& module);

struct BlockMember {
  std::string name;
  uint32_t offset = 0, size = 0;  // bytes, as laid out in the SPIR-V (std140/std430/scalar as declared)
  std::vector<BlockMember> members;
};

struct ReflectedBinding {
  uint32_t set = 0, binding = 0;
  VkDescriptorType type{};
  uint32_t count = 1;             // 0: a runtime-sized array, sized by whoever builds the layout
  VkShaderStageFlags stages = 0;  // merged across the pipeline's stages
  std::string name;
  uint32_t blockSize = 0;         // buffers only
  std::vector<BlockMember> members;
};

struct ReflectedPushConstants {
  uint32_t offset = 0, size = 0;
  VkShaderStageFlags stages = 0;
  std::string name;
  std::vector<BlockMember> members;
};

struct InterfaceVariable {
  uint32_t location = 0;
  VkFormat format{};
  std::string name;
};

struct StageInterface {
  std::string module;
  VkShaderStageFlagBits stage{};
  std::string entryPoint;
  std::array<uint32_t, 3> localSize{0, 0, 0};  // compute only
  std::vector<InterfaceVariable> inputs, outputs;  // built-ins left out
};

struct PipelineInterface {
  std::vector<StageInterface> stages;
  std::vector<ReflectedBinding> bindings;        // sorted by (set, binding)
  std::vector<ReflectedPushConstants> pushConstants;  // at most one range (one block per stage, merged)

  uint32_t setCount() const { return bindings.empty() ? 0 : bindings.back().set + 1; }
};

// Reflects every module and merges them into one pipeline interface. Two stages that declare the same
// set/binding with a different type or count, or push-constant blocks that overlap with a different
// layout, are an rtr::Error naming both shaders, the set and the binding.
PipelineInterface reflectPipeline(const std::vector<SpirvModule>& modules);

std::string toText(const PipelineInterface& p);
std::string toJson(const PipelineInterface& p);
const char* descriptorTypeName(VkDescriptorType t);
const char* formatName(VkFormat f);
std::string stageNames(VkShaderStageFlags stages);

}  // namespace rtr::vk
