#include "vk/reflect.hpp"

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>

#include <spirv-tools/libspirv.hpp>
#include <spirv_reflect/spirv_reflect.h>

#include "core/error.hpp"

namespace rtr::vk {
namespace {

struct ReflectModule {
  SpvReflectShaderModule m{};
  ReflectModule(const SpirvModule& s) {
    SpvReflectResult r = spvReflectCreateShaderModule(s.code.size() * 4, s.code.data(), &m);
    if (r != SPV_REFLECT_RESULT_SUCCESS)
      throw Error(s.name + ": not valid SPIR-V (SPIRV-Reflect error " + std::to_string(int(r)) + ")");
  }
  ~ReflectModule() { spvReflectDestroyShaderModule(&m); }
};

std::vector<BlockMember> members(const SpvReflectBlockVariable& b) {
  std::vector<BlockMember> out;
  for (uint32_t i = 0; i < b.member_count; ++i) {
    const auto& m = b.members[i];
    out.push_back({m.name ? m.name : "", m.offset, m.size, members(m)});
  }
  return out;
}

bool sameLayout(const std::vector<BlockMember>& a, const std::vector<BlockMember>& b, uint32_t lo, uint32_t hi) {
  // Members that fall inside the overlap [lo, hi) must agree in offset and size.
  auto inside = [&](const BlockMember& m) { return m.offset < hi && m.offset + m.size > lo; };
  std::vector<std::pair<uint32_t, uint32_t>> x, y;
  for (auto& m : a) if (inside(m)) x.push_back({m.offset, m.size});
  for (auto& m : b) if (inside(m)) y.push_back({m.offset, m.size});
  return x == y;
}

std::string bindingPlace(const ReflectedBinding& b) {
  return "set " + std::to_string(b.set) + " binding " + std::to_string(b.binding) + " ('" + b.name + "')";
}

}  // namespace

SpirvModule readSpirv(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) throw fileError(file.string(), "", "cannot open SPIR-V file");
  const std::streamsize size = in.tellg();
  if (size < 20 || size % 4 != 0)
    throw fileError(file.string(), "", "not SPIR-V: size " + std::to_string(size) + " is not a multiple of 4 of at least 20 bytes");
  SpirvModule m{file.filename().string(), std::vector<uint32_t>(size_t(size) / 4)};
  in.seekg(0);
  in.read(reinterpret_cast<char*>(m.code.data()), size);
  if (m.code[0] != 0x07230203u) throw fileError(file.string(), "at byte 0", "not SPIR-V: wrong magic number");
  return m;
}

void validateSpirv(const SpirvModule& module) {
  spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_3);
  std::string messages;
  tools.SetMessageConsumer([&](spv_message_level_t, const char*, const spv_position_t& pos, const char* msg) {
    messages += "\n  at word " + std::to_string(pos.index) + ": " + msg;
  });
  if (!tools.Validate(module.code)) throw Error(module.name + ": invalid SPIR-V" + messages);
}

PipelineInterface reflectPipeline(const std::vector<SpirvModule>& modules) {
  PipelineInterface out;
  std::map<std::pair<uint32_t, uint32_t>, std::pair<ReflectedBinding, std::string>> bindings;  // + first module
  struct Push { ReflectedPushConstants range; std::string module; };
  std::vector<Push> pushes;

  for (const SpirvModule& s : modules) {
    ReflectModule rm(s);
    const SpvReflectShaderModule& m = rm.m;
    if (m.entry_point_count != 1)
      throw Error(s.name + ": expected exactly one entry point, found " + std::to_string(m.entry_point_count));
    StageInterface st;
    st.module = s.name;
    st.stage = VkShaderStageFlagBits(m.shader_stage);
    st.entryPoint = m.entry_point_name;
    for (const auto& other : out.stages)
      if (other.stage == st.stage) throw Error(s.name + " and " + other.module + ": both are " + stageNames(st.stage) + " shaders");
    if (st.stage == VK_SHADER_STAGE_COMPUTE_BIT) {
      const auto& ls = m.entry_points[0].local_size;
      st.localSize = {ls.x, ls.y, ls.z};
    }
    auto vars = [](uint32_t n, SpvReflectInterfaceVariable** v) {
      std::vector<InterfaceVariable> r;
      for (uint32_t i = 0; i < n; ++i)
        if (!(v[i]->decoration_flags & SPV_REFLECT_DECORATION_BUILT_IN))
          r.push_back({v[i]->location, VkFormat(v[i]->format), v[i]->name ? v[i]->name : ""});
      std::sort(r.begin(), r.end(), [](auto& a, auto& b) { return a.location < b.location; });
      return r;
    };
    st.inputs = vars(m.input_variable_count, m.input_variables);
    st.outputs = vars(m.output_variable_count, m.output_variables);

    for (uint32_t i = 0; i < m.descriptor_binding_count; ++i) {
      const SpvReflectDescriptorBinding& d = m.descriptor_bindings[i];
      ReflectedBinding b;
      b.set = d.set;
      b.binding = d.binding;
      b.type = VkDescriptorType(d.descriptor_type);
      // SPIRV-Reflect's count is 1 for a runtime array; its type is what says "runtime".
      const bool runtime = (d.type_description && d.type_description->op == SpvOpTypeRuntimeArray) ||
                           (d.array.dims_count > 0 && d.array.dims[0] == SPV_REFLECT_ARRAY_DIM_RUNTIME);
      b.count = runtime ? 0 : d.count;
      b.stages = st.stage;
      b.name = d.name && *d.name ? d.name : (d.type_description && d.type_description->type_name ? d.type_description->type_name : "");
      if (b.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER || b.type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER) {
        b.blockSize = d.block.size;
        b.members = members(d.block);
      }
      auto key = std::make_pair(b.set, b.binding);
      auto it = bindings.find(key);
      if (it == bindings.end()) {
        bindings.emplace(key, std::make_pair(b, s.name));
        continue;
      }
      ReflectedBinding& prev = it->second.first;
      if (prev.type != b.type || prev.count != b.count)
        throw Error("stage conflict at " + bindingPlace(b) + ": " + it->second.second + " declares " +
                    descriptorTypeName(prev.type) + "[" + std::to_string(prev.count) + "], " + s.name + " declares " +
                    descriptorTypeName(b.type) + "[" + std::to_string(b.count) + "]");
      prev.stages |= b.stages;
    }

    if (m.push_constant_block_count > 1) throw Error(s.name + ": more than one push-constant block");
    if (m.push_constant_block_count == 1) {
      const SpvReflectBlockVariable& pc = m.push_constant_blocks[0];
      ReflectedPushConstants r{pc.offset, pc.size - pc.offset, VkShaderStageFlags(st.stage),
                               pc.name ? pc.name : "", members(pc)};
      for (Push& p : pushes) {
        uint32_t lo = std::max(p.range.offset, r.offset);
        uint32_t hi = std::min(p.range.offset + p.range.size, r.offset + r.size);
        if (lo < hi && !sameLayout(p.range.members, r.members, lo, hi))
          throw Error("stage conflict in push constants: " + p.module + " and " + s.name +
                      " lay out the overlapping bytes [" + std::to_string(lo) + ", " + std::to_string(hi) +
                      ") differently");
      }
      pushes.push_back({r, s.name});
    }
    out.stages.push_back(std::move(st));
  }

  for (auto& [key, value] : bindings) out.bindings.push_back(value.first);
  if (!pushes.empty()) {
    // One range covering every stage's block: Vulkan allows each stage in one range only.
    ReflectedPushConstants merged = pushes[0].range;
    uint32_t end = merged.offset + merged.size;
    for (const Push& p : pushes) {
      merged.offset = std::min(merged.offset, p.range.offset);
      end = std::max(end, p.range.offset + p.range.size);
      merged.stages |= p.range.stages;
      if (p.range.members.size() > merged.members.size()) merged.members = p.range.members;
    }
    merged.size = end - merged.offset;
    out.pushConstants.push_back(merged);
  }
  return out;
}

}  // namespace rtr::vk
