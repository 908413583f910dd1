// Text and JSON renderings of a PipelineInterface (what rtr-reflect prints).
#include <sstream>

#include "vk/reflect.hpp"

namespace rtr::vk {
namespace {

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\', out += c;
    else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else out += c;
  }
  return out + "\"";
}

void textMembers(std::ostringstream& o, const std::vector<BlockMember>& ms, int indent) {
  for (const auto& m : ms) {
    o << std::string(indent, ' ') << "+" << m.offset << " " << m.name << " (" << m.size << " bytes)";
    if (!m.pointee.empty()) {
      o << " -> " << m.pointee;  // size 0: SPIRV-Reflect did not lay the block out (arrays of 2+ dimensions)
      if (m.pointeeSize) o << " (" << m.pointeeSize << " bytes" << (m.members.empty() ? ", members listed above)" : ")");
    }
    o << "\n";
    textMembers(o, m.members, indent + 2);
  }
}

void jsonMembers(std::ostringstream& o, const std::vector<BlockMember>& ms) {
  o << "[";
  for (size_t i = 0; i < ms.size(); ++i) {
    o << (i ? "," : "") << "{\"name\":" << jsonString(ms[i].name) << ",\"offset\":" << ms[i].offset << ",\"size\":" << ms[i].size;
    if (!ms[i].pointee.empty()) o << ",\"pointee\":" << jsonString(ms[i].pointee) << ",\"pointeeSize\":" << ms[i].pointeeSize;
    if (!ms[i].members.empty()) {
      o << ",\"members\":";
      jsonMembers(o, ms[i].members);
    }
    o << "}";
  }
  o << "]";
}

void jsonVars(std::ostringstream& o, const std::vector<InterfaceVariable>& vs) {
  o << "[";
  for (size_t i = 0; i < vs.size(); ++i)
    o << (i ? "," : "") << "{\"location\":" << vs[i].location << ",\"format\":" << jsonString(formatName(vs[i].format))
      << ",\"name\":" << jsonString(vs[i].name) << "}";
  o << "]";
}

}  // namespace

std::string stageNames(VkShaderStageFlags s) {
  std::string out;
  auto add = [&](VkShaderStageFlags bit, const char* name) {
    if (s & bit) out += (out.empty() ? "" : "|") + std::string(name);
  };
  add(VK_SHADER_STAGE_VERTEX_BIT, "vertex");
  add(VK_SHADER_STAGE_TESSELLATION_CONTROL_BIT, "tess-control");
  add(VK_SHADER_STAGE_TESSELLATION_EVALUATION_BIT, "tess-eval");
  add(VK_SHADER_STAGE_GEOMETRY_BIT, "geometry");
  add(VK_SHADER_STAGE_FRAGMENT_BIT, "fragment");
  add(VK_SHADER_STAGE_COMPUTE_BIT, "compute");
  add(VK_SHADER_STAGE_TASK_BIT_EXT, "task");
  add(VK_SHADER_STAGE_MESH_BIT_EXT, "mesh");
  add(VK_SHADER_STAGE_RAYGEN_BIT_KHR, "raygen");
  add(VK_SHADER_STAGE_ANY_HIT_BIT_KHR, "any-hit");
  add(VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR, "closest-hit");
  add(VK_SHADER_STAGE_MISS_BIT_KHR, "miss");
  add(VK_SHADER_STAGE_INTERSECTION_BIT_KHR, "intersection");
  add(VK_SHADER_STAGE_CALLABLE_BIT_KHR, "callable");
  return out.empty() ? "none" : out;
}

const char* descriptorTypeName(VkDescriptorType t) {
  switch (t) {
    case VK_DESCRIPTOR_TYPE_SAMPLER: return "sampler";
    case VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER: return "combined-image-sampler";
    case VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE: return "sampled-image";
    case VK_DESCRIPTOR_TYPE_STORAGE_IMAGE: return "storage-image";
    case VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER: return "uniform-texel-buffer";
    case VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER: return "storage-texel-buffer";
    case VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER: return "uniform-buffer";
    case VK_DESCRIPTOR_TYPE_STORAGE_BUFFER: return "storage-buffer";
    case VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT: return "input-attachment";
    case VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR: return "acceleration-structure";
    default: return "other";
  }
}

const char* formatName(VkFormat f) {
  switch (f) {
    case VK_FORMAT_UNDEFINED: return "undefined";
    case VK_FORMAT_R32_SFLOAT: return "float";
    case VK_FORMAT_R32G32_SFLOAT: return "vec2";
    case VK_FORMAT_R32G32B32_SFLOAT: return "vec3";
    case VK_FORMAT_R32G32B32A32_SFLOAT: return "vec4";
    case VK_FORMAT_R32_SINT: return "int";
    case VK_FORMAT_R32G32_SINT: return "ivec2";
    case VK_FORMAT_R32G32B32_SINT: return "ivec3";
    case VK_FORMAT_R32G32B32A32_SINT: return "ivec4";
    case VK_FORMAT_R32_UINT: return "uint";
    case VK_FORMAT_R32G32_UINT: return "uvec2";
    case VK_FORMAT_R32G32B32_UINT: return "uvec3";
    case VK_FORMAT_R32G32B32A32_UINT: return "uvec4";
    default: return "other";
  }
}

std::string toText(const PipelineInterface& p) {
  auto size = [](uint32_t n) { return n == kSpecializedSize ? std::string("spec") : std::to_string(n); };
  std::ostringstream o;
  for (const auto& s : p.stages) {
    o << "stage " << stageNames(s.stage) << ": " << s.module << " entry '" << s.entryPoint << "'";
    if (s.stage == VK_SHADER_STAGE_COMPUTE_BIT)
      o << " workgroup " << size(s.localSize[0]) << "x" << size(s.localSize[1]) << "x" << size(s.localSize[2]);
    o << "\n";
    for (const auto& v : s.inputs) o << "  in  location " << v.location << " " << formatName(v.format) << " " << v.name << "\n";
    for (const auto& v : s.outputs) o << "  out location " << v.location << " " << formatName(v.format) << " " << v.name << "\n";
    for (const auto& c : s.specConstants)
      o << "  specialization constant " << c.id << " " << c.type << " " << c.name << " = " << c.defaultValue << "\n";
  }
  for (const auto& b : p.bindings) {
    o << "set " << b.set << " binding " << b.binding << ": " << descriptorTypeName(b.type);
    if (b.count != 1) o << "[" << (b.count ? std::to_string(b.count) : std::string()) << "]";
    if (b.imageFormat != VK_FORMAT_UNDEFINED) o << " " << imageFormatName(b.imageFormat);
    if (b.type == VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT) o << " input_attachment_index " << b.inputAttachmentIndex;
    o << " " << b.name << " (" << stageNames(b.stages) << ")";
    if (b.blockSize) o << " " << b.blockSize << " bytes";
    o << "\n";
    textMembers(o, b.members, 2);
  }
  for (const auto& pc : p.pushConstants) {
    o << "push constants: offset " << pc.offset << " size " << pc.size << " " << pc.name << " (" << stageNames(pc.stages)
      << ")\n";
    textMembers(o, pc.members, 2);
  }
  return o.str();
}

std::string toJson(const PipelineInterface& p) {
  auto size = [](uint32_t n) { return n == kSpecializedSize ? std::string("null") : std::to_string(n); };
  std::ostringstream o;
  o << "{\"stages\":[";
  for (size_t i = 0; i < p.stages.size(); ++i) {
    const auto& s = p.stages[i];
    o << (i ? "," : "") << "{\"module\":" << jsonString(s.module) << ",\"stage\":" << jsonString(stageNames(s.stage))
      << ",\"entryPoint\":" << jsonString(s.entryPoint);
    if (s.stage == VK_SHADER_STAGE_COMPUTE_BIT)
      o << ",\"workgroupSize\":[" << size(s.localSize[0]) << "," << size(s.localSize[1]) << "," << size(s.localSize[2]) << "]";
    o << ",\"inputs\":";
    jsonVars(o, s.inputs);
    o << ",\"outputs\":";
    jsonVars(o, s.outputs);
    if (!s.specConstants.empty()) {
      o << ",\"specConstants\":[";
      for (size_t j = 0; j < s.specConstants.size(); ++j) {
        const auto& c = s.specConstants[j];
        o << (j ? "," : "") << "{\"id\":" << c.id << ",\"name\":" << jsonString(c.name) << ",\"type\":" << jsonString(c.type)
          << ",\"default\":" << jsonString(c.defaultValue) << "}";
      }
      o << "]";
    }
    o << "}";
  }
  o << "],\"descriptorSets\":[";
  for (size_t i = 0; i < p.bindings.size(); ++i) {
    const auto& b = p.bindings[i];
    o << (i ? "," : "") << "{\"set\":" << b.set << ",\"binding\":" << b.binding
      << ",\"type\":" << jsonString(descriptorTypeName(b.type)) << ",\"count\":" << b.count
      << ",\"runtimeArray\":" << (b.count == 0 ? "true" : "false") << ",\"name\":" << jsonString(b.name)
      << ",\"stages\":" << jsonString(stageNames(b.stages));
    if (b.imageFormat != VK_FORMAT_UNDEFINED) o << ",\"imageFormat\":" << jsonString(imageFormatName(b.imageFormat));
    if (b.type == VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT) o << ",\"inputAttachmentIndex\":" << b.inputAttachmentIndex;
    if (b.blockSize) {
      o << ",\"blockSize\":" << b.blockSize << ",\"members\":";
      jsonMembers(o, b.members);
    }
    o << "}";
  }
  o << "],\"pushConstants\":[";
  for (size_t i = 0; i < p.pushConstants.size(); ++i) {
    const auto& pc = p.pushConstants[i];
    o << (i ? "," : "") << "{\"offset\":" << pc.offset << ",\"size\":" << pc.size << ",\"name\":" << jsonString(pc.name)
      << ",\"stages\":" << jsonString(stageNames(pc.stages)) << ",\"members\":";
    jsonMembers(o, pc.members);
    o << "}";
  }
  o << "]}\n";
  return o.str();
}

}  // namespace rtr::vk
