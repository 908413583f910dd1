#pragma once
// A pipeline's interface read from its SPIR-V with SPIRV-Reflect: the one source of every descriptor
// set layout and push-constant range in the project (none is written by hand), and what rtr-reflect prints.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

namespace rtr::vk {

struct SpirvModule {
  std::string name;  // file name, for messages
  std::vector<uint32_t> code;
};

// Reads a .spv file; a wrong size or magic number is an rtr::Error naming the file.
SpirvModule readSpirv(const std::filesystem::path& file);
// Bytes in memory as a module: a size that is not a whole number of words, or a wrong magic number, is an
// rtr::Error naming `name`.
SpirvModule spirvFromBytes(const void* data, size_t size, const std::string& name);
// Runs the SPIRV-Tools validator (Vulkan 1.3 rules); throws rtr::Error with its message. The validator is
// Debian's and may be older than the compiler that wrote the module (Slang, a newer glslang): rtr-reflect
// reports its verdict as a warning unless --strict.
void validateSpirv(const SpirvModule& module);

struct BlockMember {
  std::string name;
  uint32_t offset = 0, size = 0;     // bytes, as laid out in the SPIR-V (std140/std430/scalar as declared)
  std::vector<BlockMember> members;  // a struct's members, or the members of the block a reference points to
  // A buffer reference (GL_EXT_buffer_reference), or an array of them: the block type it points to and
  // that block's size. A block's members are listed at its first reference within one binding only; a
  // later reference to it (a linked list's `next`) names it and lists none, so the tree stays finite.
  std::string pointee;
  uint32_t pointeeSize = 0;
};

struct ReflectedBinding {
  uint32_t set = 0, binding = 0;
  VkDescriptorType type{};
  uint32_t count = 1;             // 0: a runtime-sized array, sized by whoever builds the layout
  VkShaderStageFlags stages = 0;  // merged across the pipeline's stages
  std::string name;
  uint32_t blockSize = 0;  // buffers only: end of the last member (a runtime array counts 0)
  std::vector<BlockMember> members;
  VkFormat imageFormat = VK_FORMAT_UNDEFINED;  // storage images and texel buffers that declare one
  uint32_t inputAttachmentIndex = 0;           // input attachments only
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

struct SpecConstant {
  uint32_t id = 0;
  std::string name, type, defaultValue;  // type: bool, int, uint, float, ...; the default as written
};

constexpr uint32_t kSpecializedSize = UINT32_MAX;

// One entry point. A module with several (as Slang writes them) gives one StageInterface for each, each
// with the resources its own code uses.
struct StageInterface {
  std::string module;
  VkShaderStageFlagBits stage{};
  std::string entryPoint;
  std::array<uint32_t, 3> localSize{0, 0, 0};      // compute only; kSpecializedSize: set by a spec constant
  std::vector<InterfaceVariable> inputs, outputs;  // built-ins left out
  std::vector<SpecConstant> specConstants;         // the module's, sorted by id
};

struct PipelineInterface {
  std::vector<StageInterface> stages;
  std::vector<ReflectedBinding> bindings;             // sorted by (set, binding)
  std::vector<ReflectedPushConstants> pushConstants;  // at most one range (one block per stage, merged)

  uint32_t setCount() const { return bindings.empty() ? 0 : bindings.back().set + 1; }
};

// Reflects every module and merges them into one pipeline interface. Two stages that declare the same
// set/binding with a different type or count, or push-constant blocks that overlap with a different
// layout, are an rtr::Error naming both shaders, the set and the binding.
PipelineInterface reflectPipeline(const std::vector<SpirvModule>& modules);

// One module given as bytes (no file, no spirv-val) reflected and rendered as toText or toJson would;
// bad input of any kind is an rtr::Error, never a crash. The SPIR-V fuzz target calls this.
std::string reflectSpirvBytes(const void* data, size_t size, bool json = false);

std::string toText(const PipelineInterface& p);
std::string toJson(const PipelineInterface& p);
const char* descriptorTypeName(VkDescriptorType t);
const char* formatName(VkFormat f);       // vertex inputs and fragment outputs: "vec4", "uint", ...
const char* imageFormatName(VkFormat f);  // storage images: GLSL's layout names, "rgba8", "r32ui", ...
std::string stageNames(VkShaderStageFlags stages);

}  // namespace rtr::vk
