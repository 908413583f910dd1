#include "vk/reflect.hpp"

#include <algorithm>
#include <cstring>
#include <map>
#include <set>
#include <sstream>

#include <spirv-tools/libspirv.hpp>
#include <spirv_reflect/spirv_reflect.h>

#include "core/error.hpp"
#include "core/input_file.hpp"

namespace rtr::vk {
namespace {

constexpr uint64_t kMaxSpirvBytes = uint64_t(64) << 20;  // our largest module is a few hundred KB

const char* resultName(SpvReflectResult r) {
  static const char* const names[] = {"success",
                                      "not ready",
                                      "parse failed",
                                      "allocation failed",
                                      "range exceeded",
                                      "null pointer",
                                      "internal error",
                                      "count mismatch",
                                      "element not found",
                                      "invalid code size",
                                      "invalid magic number",
                                      "unexpected end of file",
                                      "invalid id reference",
                                      "set number overflow",
                                      "invalid storage class",
                                      "recursion",
                                      "invalid instruction",
                                      "unexpected block data",
                                      "invalid block member reference",
                                      "invalid entry point",
                                      "invalid execution mode",
                                      "too deeply recursive"};
  return size_t(r) < std::size(names) ? names[r] : "unknown error";
}

// SPIRV-Reflect (Debian's build keeps its asserts) aborts on an instruction that runs past the end of
// the module, so the instruction stream is walked first.
void checkInstructionStream(const SpirvModule& s) {
  const std::vector<uint32_t>& w = s.code;
  if (w.size() < 5) throw fileError(s.name, "", "not SPIR-V: shorter than its 5-word header");
  for (size_t i = 5; i < w.size();) {
    const uint32_t words = w[i] >> 16;
    if (words == 0 || words > w.size() - i)
      throw fileError(
          s.name, "word " + std::to_string(i),
          "not SPIR-V: an instruction of " + std::to_string(words) + " words in a module of " + std::to_string(w.size()));
    i += words;
  }
}

struct ReflectModule {
  SpvReflectShaderModule m{};
  ReflectModule(const SpirvModule& s) {
    checkInstructionStream(s);
    SpvReflectResult r = spvReflectCreateShaderModule(s.code.size() * 4, s.code.data(), &m);
    if (r != SPV_REFLECT_RESULT_SUCCESS)
      throw Error(s.name + ": SPIRV-Reflect cannot read this module (" + resultName(r) + ", error " + std::to_string(int(r)) +
                  ")");
  }
  ~ReflectModule() { spvReflectDestroyShaderModule(&m); }
};

constexpr uint32_t kPointerSize = 8;  // PhysicalStorageBuffer64, the only addressing model Vulkan has

bool isReference(const SpvReflectBlockVariable& v) {
  return v.type_description && (v.type_description->type_flags & SPV_REFLECT_TYPE_FLAG_REF);
}

uint32_t clamp32(uint64_t x) { return uint32_t(std::min<uint64_t>(x, UINT32_MAX)); }

// SPIRV-Reflect leaves the size 0 for a reference to a block it has laid out before and for arrays of
// references; both follow from the type. A runtime array stays 0.
uint32_t memberSize(const SpvReflectBlockVariable& v) {
  const SpvReflectTypeDescription* t = v.type_description;
  if (v.size || !t) return v.size;
  if (t->type_flags & SPV_REFLECT_TYPE_FLAG_ARRAY) {
    const SpvReflectArrayTraits& a = t->traits.array;  // stride: the innermost element's
    uint64_t n = a.stride;
    for (uint32_t i = 0; i < std::min<uint32_t>(a.dims_count, SPV_REFLECT_MAX_ARRAY_DIMS); ++i)
      n = std::min<uint64_t>(n * a.dims[i], UINT32_MAX);  // a runtime dimension is 0
    return clamp32(n);
  }
  return isReference(v) ? kPointerSize : 0;
}

uint32_t blockEnd(const SpvReflectBlockVariable& b) {
  uint64_t end = 0;
  for (uint32_t i = 0; i < b.member_count; ++i) end = std::max(end, uint64_t(b.members[i].offset) + memberSize(b.members[i]));
  return clamp32(end);
}

// `listed` holds the member arrays already converted within one top-level block. SPIRV-Reflect gives
// every reference to a block the same member array, so a pointer cycle (a list node's `next`) comes back
// to one already listed: it is named, not listed again.
std::vector<BlockMember> members(const SpvReflectBlockVariable& b, std::set<const void*>& listed) {
  std::vector<BlockMember> out;
  for (uint32_t i = 0; i < b.member_count; ++i) {
    const SpvReflectBlockVariable& m = b.members[i];
    BlockMember bm{m.name ? m.name : "", m.offset, memberSize(m), {}, {}, 0};
    if (isReference(m)) {
      const char* type = m.type_description->type_name;
      bm.pointee = type && *type ? type : "buffer reference";
      bm.pointeeSize = blockEnd(m);
    }
    if (m.member_count && listed.insert(m.members).second) bm.members = members(m, listed);
    out.push_back(std::move(bm));
  }
  return out;
}

std::vector<BlockMember> members(const SpvReflectBlockVariable& b) {
  std::set<const void*> listed{b.members};
  return members(b, listed);
}

bool sameLayout(const std::vector<BlockMember>& a, const std::vector<BlockMember>& b, uint32_t lo, uint32_t hi) {
  // Members that fall inside the overlap [lo, hi) must agree in offset and size.
  auto inside = [&](const BlockMember& m) { return m.offset < hi && m.offset + m.size > lo; };
  std::vector<std::pair<uint32_t, uint32_t>> x, y;
  for (auto& m : a)
    if (inside(m)) x.push_back({m.offset, m.size});
  for (auto& m : b)
    if (inside(m)) y.push_back({m.offset, m.size});
  return x == y;
}

std::string bindingPlace(const ReflectedBinding& b) {
  return "set " + std::to_string(b.set) + " binding " + std::to_string(b.binding) + " ('" + b.name + "')";
}

// SpvImageFormat, which numbers its values 0..41, to Vulkan's format and GLSL's layout name.
struct ImageFormat {
  VkFormat vk;
  const char* name;
};
constexpr ImageFormat kImageFormats[] = {{VK_FORMAT_UNDEFINED, "unknown"},
                                         {VK_FORMAT_R32G32B32A32_SFLOAT, "rgba32f"},
                                         {VK_FORMAT_R16G16B16A16_SFLOAT, "rgba16f"},
                                         {VK_FORMAT_R32_SFLOAT, "r32f"},
                                         {VK_FORMAT_R8G8B8A8_UNORM, "rgba8"},
                                         {VK_FORMAT_R8G8B8A8_SNORM, "rgba8_snorm"},
                                         {VK_FORMAT_R32G32_SFLOAT, "rg32f"},
                                         {VK_FORMAT_R16G16_SFLOAT, "rg16f"},
                                         {VK_FORMAT_B10G11R11_UFLOAT_PACK32, "r11f_g11f_b10f"},
                                         {VK_FORMAT_R16_SFLOAT, "r16f"},
                                         {VK_FORMAT_R16G16B16A16_UNORM, "rgba16"},
                                         {VK_FORMAT_A2B10G10R10_UNORM_PACK32, "rgb10_a2"},
                                         {VK_FORMAT_R16G16_UNORM, "rg16"},
                                         {VK_FORMAT_R8G8_UNORM, "rg8"},
                                         {VK_FORMAT_R16_UNORM, "r16"},
                                         {VK_FORMAT_R8_UNORM, "r8"},
                                         {VK_FORMAT_R16G16B16A16_SNORM, "rgba16_snorm"},
                                         {VK_FORMAT_R16G16_SNORM, "rg16_snorm"},
                                         {VK_FORMAT_R8G8_SNORM, "rg8_snorm"},
                                         {VK_FORMAT_R16_SNORM, "r16_snorm"},
                                         {VK_FORMAT_R8_SNORM, "r8_snorm"},
                                         {VK_FORMAT_R32G32B32A32_SINT, "rgba32i"},
                                         {VK_FORMAT_R16G16B16A16_SINT, "rgba16i"},
                                         {VK_FORMAT_R8G8B8A8_SINT, "rgba8i"},
                                         {VK_FORMAT_R32_SINT, "r32i"},
                                         {VK_FORMAT_R32G32_SINT, "rg32i"},
                                         {VK_FORMAT_R16G16_SINT, "rg16i"},
                                         {VK_FORMAT_R8G8_SINT, "rg8i"},
                                         {VK_FORMAT_R16_SINT, "r16i"},
                                         {VK_FORMAT_R8_SINT, "r8i"},
                                         {VK_FORMAT_R32G32B32A32_UINT, "rgba32ui"},
                                         {VK_FORMAT_R16G16B16A16_UINT, "rgba16ui"},
                                         {VK_FORMAT_R8G8B8A8_UINT, "rgba8ui"},
                                         {VK_FORMAT_R32_UINT, "r32ui"},
                                         {VK_FORMAT_A2B10G10R10_UINT_PACK32, "rgb10_a2ui"},
                                         {VK_FORMAT_R32G32_UINT, "rg32ui"},
                                         {VK_FORMAT_R16G16_UINT, "rg16ui"},
                                         {VK_FORMAT_R8G8_UINT, "rg8ui"},
                                         {VK_FORMAT_R16_UINT, "r16ui"},
                                         {VK_FORMAT_R8_UINT, "r8ui"},
                                         {VK_FORMAT_R64_UINT, "r64ui"},
                                         {VK_FORMAT_R64_SINT, "r64i"}};

SpecConstant specConstant(const SpvReflectSpecializationConstant& c) {
  SpecConstant out{c.constant_id, c.name ? c.name : "", "", ""};
  const SpvReflectTypeDescription* t = c.type_description;
  const uint32_t* words = static_cast<const uint32_t*>(c.default_value);
  if (!t || !words || c.default_value_size < 4) return out;
  const uint32_t width = t->traits.numeric.scalar.width;
  uint64_t bits = words[0];
  if (width == 64 && c.default_value_size >= 8) bits |= uint64_t(words[1]) << 32;
  if (t->type_flags & SPV_REFLECT_TYPE_FLAG_BOOL) {
    out.type = "bool";
    out.defaultValue = bits ? "true" : "false";
  } else if (t->type_flags & SPV_REFLECT_TYPE_FLAG_FLOAT) {
    out.type = "float" + std::to_string(width);
    std::ostringstream v;
    if (width == 32) {
      float f;
      std::memcpy(&f, &bits, 4);
      v << f;
    } else if (width == 64) {
      double d;
      std::memcpy(&d, &bits, 8);
      v << d;
    } else v << "0x" << std::hex << bits;
    out.defaultValue = v.str();
  } else if (t->type_flags & SPV_REFLECT_TYPE_FLAG_INT) {
    const bool sign = t->traits.numeric.scalar.signedness;
    out.type = (sign ? "int" : "uint") + std::to_string(width);
    if (width < 64) bits &= (uint64_t(1) << width) - 1;
    const bool negative = sign && width && width <= 64 && (bits >> (width - 1)) & 1;
    out.defaultValue = negative ? std::to_string(int64_t(bits | (width < 64 ? ~0ull << width : 0))) : std::to_string(bits);
  }
  return out;
}

// What one entry point of a module uses. A module with one entry point keeps every resource it declares
// (a layout shared by several shaders may declare more than one of them uses); with several, each
// entry point gets the ones its own code reaches, as SPIRV-Reflect finds them.
struct EntryResources {
  std::vector<const SpvReflectDescriptorBinding*> bindings;
  const SpvReflectBlockVariable* push = nullptr;
};

EntryResources entryResources(const SpirvModule& s, const SpvReflectShaderModule& m, const SpvReflectEntryPoint& e) {
  EntryResources r;
  std::vector<const SpvReflectBlockVariable*> pushes;
  if (m.entry_point_count == 1) {
    for (uint32_t i = 0; i < m.descriptor_binding_count; ++i) r.bindings.push_back(&m.descriptor_bindings[i]);
    for (uint32_t i = 0; i < m.push_constant_block_count; ++i) pushes.push_back(&m.push_constant_blocks[i]);
  } else {
    for (uint32_t i = 0; i < e.descriptor_set_count; ++i)
      for (uint32_t j = 0; j < e.descriptor_sets[i].binding_count; ++j) r.bindings.push_back(e.descriptor_sets[i].bindings[j]);
    for (uint32_t i = 0; i < m.push_constant_block_count; ++i)
      for (uint32_t j = 0; j < e.used_push_constant_count; ++j)
        if (m.push_constant_blocks[i].spirv_id == e.used_push_constants[j]) pushes.push_back(&m.push_constant_blocks[i]);
  }
  if (pushes.size() > 1) throw Error(s.name + ": more than one push-constant block");
  if (!pushes.empty()) r.push = pushes[0];
  return r;
}

ReflectedBinding binding(const SpvReflectDescriptorBinding& d, VkShaderStageFlagBits stage) {
  ReflectedBinding b;
  b.set = d.set;
  b.binding = d.binding;
  b.type = VkDescriptorType(d.descriptor_type);
  // SPIRV-Reflect's count is 1 for a runtime array; its type is what says "runtime".
  const bool runtime = (d.type_description && d.type_description->op == SpvOpTypeRuntimeArray) ||
                       (d.array.dims_count > 0 && d.array.dims[0] == SPV_REFLECT_ARRAY_DIM_RUNTIME);
  b.count = runtime ? 0 : d.count;
  b.stages = stage;
  b.name =
      d.name && *d.name ? d.name : (d.type_description && d.type_description->type_name ? d.type_description->type_name : "");
  if (b.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER || b.type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER) {
    // SPIRV-Reflect gives 0 for storage buffers: the members say where the block ends.
    b.blockSize = d.block.size ? d.block.size : blockEnd(d.block);
    b.members = members(d.block);
  }
  if (b.type == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE || b.type == VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER ||
      b.type == VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER)
    if (size_t(d.image.image_format) < std::size(kImageFormats)) b.imageFormat = kImageFormats[d.image.image_format].vk;
  if (b.type == VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT) b.inputAttachmentIndex = d.input_attachment_index;
  return b;
}

}  // namespace

const char* imageFormatName(VkFormat f) {
  for (const ImageFormat& i : kImageFormats)
    if (i.vk == f) return i.name;
  return "other";
}

SpirvModule spirvFromBytes(const void* data, size_t size, const std::string& name) {
  if (size < 20 || size % 4 != 0)
    throw fileError(name, "", "not SPIR-V: size " + std::to_string(size) + " is not a multiple of 4 of at least 20 bytes");
  SpirvModule m{name, std::vector<uint32_t>(size / 4)};
  std::memcpy(m.code.data(), data, size);
  if (m.code[0] != 0x07230203u) throw fileError(name, "byte 0", "not SPIR-V: wrong magic number");
  return m;
}

SpirvModule readSpirv(const std::filesystem::path& file) {
  const std::string bytes = readInputFile(file, "SPIR-V file", kMaxSpirvBytes);
  SpirvModule m = spirvFromBytes(bytes.data(), bytes.size(), file.string());
  m.name = file.filename().string();
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
  struct Push {
    ReflectedPushConstants range;
    std::string module;
  };
  std::vector<Push> pushes;

  for (const SpirvModule& s : modules) {
    ReflectModule rm(s);
    const SpvReflectShaderModule& m = rm.m;
    if (m.entry_point_count == 0) throw Error(s.name + ": no entry point");
    std::vector<SpecConstant> specs;
    for (uint32_t i = 0; i < m.spec_constant_count; ++i) specs.push_back(specConstant(m.spec_constants[i]));
    // SPIRV-Reflect may list one constant twice (glslang's local_size_x_id): one entry per id.
    std::stable_sort(specs.begin(), specs.end(), [](auto& a, auto& b) { return a.id < b.id; });
    specs.erase(std::unique(specs.begin(), specs.end(), [](auto& a, auto& b) { return a.id == b.id; }), specs.end());

    for (uint32_t e = 0; e < m.entry_point_count; ++e) {
      const SpvReflectEntryPoint& ep = m.entry_points[e];
      StageInterface st;
      st.module = s.name;
      st.stage = VkShaderStageFlagBits(ep.shader_stage);
      st.entryPoint = ep.name ? ep.name : "";
      st.specConstants = specs;
      // A ray-tracing pipeline may hold any number of shaders of each of its stages (its shader groups
      // pick them); any other pipeline one per stage.
      constexpr VkShaderStageFlags kRayTracing = VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_ANY_HIT_BIT_KHR |
                                                 VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR | VK_SHADER_STAGE_MISS_BIT_KHR |
                                                 VK_SHADER_STAGE_INTERSECTION_BIT_KHR | VK_SHADER_STAGE_CALLABLE_BIT_KHR;
      for (const auto& other : out.stages)
        if (other.stage == st.stage && !(st.stage & kRayTracing))
          throw Error(s.name + " '" + st.entryPoint + "' and " + other.module + " '" + other.entryPoint + "': both are " +
                      stageNames(st.stage) + " shaders");
      if (st.stage == VK_SHADER_STAGE_COMPUTE_BIT) st.localSize = {ep.local_size.x, ep.local_size.y, ep.local_size.z};
      auto vars = [](uint32_t n, SpvReflectInterfaceVariable** v) {
        std::vector<InterfaceVariable> r;
        for (uint32_t i = 0; i < n; ++i)
          if (!(v[i]->decoration_flags & SPV_REFLECT_DECORATION_BUILT_IN))
            r.push_back({v[i]->location, VkFormat(v[i]->format), v[i]->name ? v[i]->name : ""});
        std::sort(r.begin(), r.end(), [](auto& a, auto& b) { return a.location < b.location; });
        return r;
      };
      st.inputs = vars(ep.input_variable_count, ep.input_variables);
      st.outputs = vars(ep.output_variable_count, ep.output_variables);

      const EntryResources res = entryResources(s, m, ep);
      for (const SpvReflectDescriptorBinding* d : res.bindings) {
        ReflectedBinding b = binding(*d, st.stage);
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

      if (const SpvReflectBlockVariable* pc = res.push) {
        // SPIRV-Reflect's size misses a trailing array of buffer references; the members tell.
        const uint32_t end = std::max(pc->size, blockEnd(*pc));
        ReflectedPushConstants r{pc->offset, end - std::min(pc->offset, end), VkShaderStageFlags(st.stage),
                                 pc->name ? pc->name : "", members(*pc)};
        for (Push& p : pushes) {
          uint32_t lo = std::max(p.range.offset, r.offset);
          uint32_t hi = std::min(p.range.offset + p.range.size, r.offset + r.size);
          if (lo < hi && !sameLayout(p.range.members, r.members, lo, hi))
            throw Error("stage conflict in push constants: " + p.module + " and " + s.name + " lay out the overlapping bytes [" +
                        std::to_string(lo) + ", " + std::to_string(hi) + ") differently");
        }
        pushes.push_back({r, s.name});
      }
      out.stages.push_back(std::move(st));
    }
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

std::string reflectSpirvBytes(const void* data, size_t size, bool json) {
  const PipelineInterface p = reflectPipeline({spirvFromBytes(data, size, "<memory>")});
  return json ? toJson(p) : toText(p);
}

}  // namespace rtr::vk
