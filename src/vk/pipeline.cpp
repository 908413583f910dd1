#include "vk/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <cstdlib>
#include <mutex>
#include <optional>
#include <unistd.h>
#include <unordered_map>

#include <spirv-tools/optimizer.hpp>

#include "core/parallel.hpp"
#include "vk/check.hpp"
#include "vk/context.hpp"
#include "vk/pipeline_cache.hpp"
#include "vk/pipeline_executables.hpp"

namespace rtr::vk {

std::filesystem::path shaderDir() {
  if (const char* env = std::getenv("RTR_SHADER_DIR")) return env;
  std::error_code ec;
  auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec && std::filesystem::exists(exe.parent_path().parent_path() / "shaders"))
    return exe.parent_path().parent_path() / "shaders";
  return RTR_SPIRV_DIR;
}

namespace {
std::mutex g_overrideMutex;
std::map<std::string, SpirvModule> g_overrides;
}  // namespace

void setShaderOverride(const std::string& name, SpirvModule module) {
  std::lock_guard lock(g_overrideMutex);
  g_overrides[name] = std::move(module);
}

SpirvModule loadShader(const std::string& name) {
  {
    std::lock_guard lock(g_overrideMutex);
    if (auto it = g_overrides.find(name); it != g_overrides.end()) return it->second;
  }
  return readSpirv(shaderDir() / (name + ".spv"));
}

SpirvModule specialize(const SpirvModule& module, const std::vector<SpecializationConstant>& constants) {
  if (constants.empty()) return module;
  std::unordered_map<uint32_t, std::vector<uint32_t>> values;
  for (const SpecializationConstant& c : constants) values[c.id] = {c.value};
  // What a driver does with VkSpecializationInfo, done here so that reflection sees the variant: the
  // constants become plain ones, branches on them fold, and what no branch left reaches goes, with the
  // inputs, outputs and descriptors only it used.
  spvtools::Optimizer opt(SPV_ENV_VULKAN_1_3);
  std::string log;
  opt.SetMessageConsumer([&](spv_message_level_t, const char*, const spv_position_t& at, const char* message) {
    log += (log.empty() ? "" : "; ") + std::string(message) + " (word " + std::to_string(at.index) + ")";
  });
  opt.RegisterPass(spvtools::CreateSetSpecConstantDefaultValuePass(values))
      .RegisterPass(spvtools::CreateFreezeSpecConstantValuePass())
      .RegisterPass(spvtools::CreateFoldSpecConstantOpAndCompositePass())
      .RegisterPass(spvtools::CreateCCPPass())  // `CONSTANT && x` in a condition, too
      .RegisterPass(spvtools::CreateDeadBranchElimPass())
      .RegisterPass(spvtools::CreateAggressiveDCEPass())
      .RegisterPass(spvtools::CreateRemoveUnusedInterfaceVariablesPass())
      .RegisterPass(spvtools::CreateEliminateDeadConstantPass());
  spvtools::OptimizerOptions options;
  options.set_run_validator(false);  // the build checked every module with spirv-val
  SpirvModule out{module.name, {}};
  if (!opt.Run(module.code.data(), module.code.size(), &out.code, options))
    throw Error(module.name + ": cannot apply its specialization constants: " + log);
  return out;
}

PipelineLayout::PipelineLayout(const Context& ctx, PipelineInterface interface, const LayoutOptions& options)
    : interface_(std::move(interface)), options_(options) {
  VkDevice device = ctx.device();
  for (uint32_t set = 0; set < interface_.setCount(); ++set) {
    std::vector<VkDescriptorSetLayoutBinding> bindings;
    std::vector<VkDescriptorBindingFlags> flags;
    bool variable = false;
    for (const ReflectedBinding& b : interface_.bindings) {
      if (b.set != set) continue;
      bindings.push_back({b.binding, b.type, arrayCount(b), b.stages, nullptr});
      // Only the highest binding of a set may have a variable count; runtime arrays are declared last.
      // Where the device allows it, elements no pending frame uses may be written (textures arriving).
      const VkDescriptorBindingFlags pending =
          ctx.updateUnusedWhilePending() ? VK_DESCRIPTOR_BINDING_UPDATE_UNUSED_WHILE_PENDING_BIT : 0;
      flags.push_back(b.count == 0 ? VK_DESCRIPTOR_BINDING_PARTIALLY_BOUND_BIT |
                                         VK_DESCRIPTOR_BINDING_VARIABLE_DESCRIPTOR_COUNT_BIT | pending
                                   : 0);
      variable |= b.count == 0;
    }
    VkDescriptorSetLayoutBindingFlagsCreateInfo fi{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO};
    fi.bindingCount = uint32_t(flags.size());
    fi.pBindingFlags = flags.data();
    VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO, variable ? &fi : nullptr};
    const auto& pushSets = options_.pushDescriptorSets;
    if (std::find(pushSets.begin(), pushSets.end(), set) != pushSets.end())
      li.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
    li.bindingCount = uint32_t(bindings.size());
    li.pBindings = bindings.data();
    VkDescriptorSetLayout raw;
    VK_CHECK(vkCreateDescriptorSetLayout(device, &li, nullptr, &raw));
    sets_.emplace_back(device, raw);
  }
  std::vector<VkDescriptorSetLayout> raw(sets_.begin(), sets_.end());
  std::vector<VkPushConstantRange> ranges;
  for (const auto& pc : interface_.pushConstants) ranges.push_back({pc.stages, pc.offset, pc.size});
  VkPipelineLayoutCreateInfo pi{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pi.setLayoutCount = uint32_t(raw.size());
  pi.pSetLayouts = raw.data();
  pi.pushConstantRangeCount = uint32_t(ranges.size());
  pi.pPushConstantRanges = ranges.data();
  VkPipelineLayout layout;
  VK_CHECK(vkCreatePipelineLayout(device, &pi, nullptr, &layout));
  layout_ = PipelineLayoutHandle(device, layout);
}

const ReflectedBinding& PipelineLayout::binding(uint32_t set, uint32_t binding) const {
  for (const auto& b : interface_.bindings)
    if (b.set == set && b.binding == binding) return b;
  throw Error("no set " + std::to_string(set) + " binding " + std::to_string(binding) + " in the pipeline's shaders");
}

bool PipelineLayout::hasBinding(uint32_t set, uint32_t binding) const {
  return std::any_of(interface_.bindings.begin(), interface_.bindings.end(),
                     [&](const ReflectedBinding& b) { return b.set == set && b.binding == binding; });
}

uint32_t PipelineLayout::arrayCount(const ReflectedBinding& b) const {
  if (b.count != 0) return b.count;
  auto it = options_.runtimeArrayCounts.find({b.set, b.binding});
  if (it == options_.runtimeArrayCounts.end() || it->second == 0)
    throw Error("runtime array '" + b.name + "' (set " + std::to_string(b.set) + " binding " + std::to_string(b.binding) +
                ") needs a count in LayoutOptions");
  return it->second;
}

void Pipeline::throwPushSizeMismatch(size_t size) const {
  const auto& pcs = layout.interface().pushConstants;
  throw Error("push constants of " + std::to_string(size) + " bytes, but the shaders declare " +
              (pcs.empty() ? std::string("none") : std::to_string(pcs[0].offset + pcs[0].size) + " bytes"));
}

namespace {

ShaderModuleHandle createModule(VkDevice device, const SpirvModule& m) {
  VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  ci.codeSize = m.code.size() * 4;
  ci.pCode = m.code.data();
  VkShaderModule raw;
  VK_CHECK(vkCreateShaderModule(device, &ci, nullptr, &raw));
  return ShaderModuleHandle(device, raw);
}

uint32_t formatSize(VkFormat f) {
  switch (f) {
    case VK_FORMAT_R32_SFLOAT:
    case VK_FORMAT_R32_UINT:
    case VK_FORMAT_R32_SINT: return 4;
    case VK_FORMAT_R32G32_SFLOAT:
    case VK_FORMAT_R32G32_UINT:
    case VK_FORMAT_R32G32_SINT: return 8;
    case VK_FORMAT_R32G32B32_SFLOAT:
    case VK_FORMAT_R32G32B32_UINT:
    case VK_FORMAT_R32G32B32_SINT: return 12;
    case VK_FORMAT_R32G32B32A32_SFLOAT:
    case VK_FORMAT_R32G32B32A32_UINT:
    case VK_FORMAT_R32G32B32A32_SINT: return 16;
    default: throw Error(std::string("vertex input of unsupported format ") + formatName(f));
  }
}

// Creation feedback for one pipeline (core in Vulkan 1.3), handed to the cache's counters, which also
// time the creation from construction (reflection and layouts included) to destruction.
struct Feedback {
  VkPipelineCreationFeedback pipeline{};
  std::vector<VkPipelineCreationFeedback> stages;
  VkPipelineCreationFeedbackCreateInfo info{VK_STRUCTURE_TYPE_PIPELINE_CREATION_FEEDBACK_CREATE_INFO};
  const Context& ctx;
  bool created = false;
  Feedback(const Context& c, size_t stageCount) : stages(stageCount), ctx(c) {
    info.pPipelineCreationFeedback = &pipeline;
    info.pipelineStageCreationFeedbackCount = uint32_t(stages.size());
    info.pPipelineStageCreationFeedbacks = stages.data();
    ctx.pipelineCache().begin();
  }
  ~Feedback() { ctx.pipelineCache().end(created ? &pipeline : nullptr); }
  Feedback(const Feedback&) = delete;
  Feedback& operator=(const Feedback&) = delete;
};

// A pipeline's name in the statistics: its shaders and specialization constants.
std::string pipelineName(const std::vector<SpirvModule>& modules, const std::vector<SpecializationConstant>& constants) {
  std::string name;
  for (const SpirvModule& m : modules) name += (name.empty() ? "" : " + ") + m.name;
  for (size_t i = 0; i < constants.size(); ++i)
    name += (i ? ", " : " {") + std::to_string(constants[i].id) + "=" + std::to_string(constants[i].value);
  return constants.empty() ? name : name + "}";
}

VkPipelineCreateFlags captureFlags(const Context& ctx) {
  return ctx.pipelineExecutables().capturing() ? VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR : 0;
}

}  // namespace

Pipeline makeComputePipeline(const Context& ctx, const SpirvModule& shader, const LayoutOptions& options,
                             const std::vector<SpecializationConstant>& specialization) {
  Feedback feedback(ctx, 1);
  Pipeline p;
  p.bindPoint = VK_PIPELINE_BIND_POINT_COMPUTE;
  const SpirvModule variant = specialize(shader, specialization);
  p.layout = PipelineLayout(ctx, reflectPipeline({variant}), options);
  ShaderModuleHandle module = createModule(ctx.device(), variant);
  VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO, &feedback.info};
  ci.flags = captureFlags(ctx);
  ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = module;
  ci.stage.pName = p.layout.interface().stages[0].entryPoint.c_str();
  ci.layout = p.layout.handle();
  VkPipeline raw;
  VK_CHECK(vkCreateComputePipelines(ctx.device(), ctx.pipelineCache().handle(), 1, &ci, nullptr, &raw));
  p.pipeline = PipelineHandle(ctx.device(), raw);
  feedback.created = true;
  ctx.setName(uint64_t(raw), VK_OBJECT_TYPE_PIPELINE, shader.name.c_str());
  ctx.pipelineExecutables().record(pipelineName({shader}, specialization), raw);
  return p;
}

Pipeline makeGraphicsPipeline(const Context& ctx, const GraphicsDesc& d, const LayoutOptions& options) {
  Feedback feedback(ctx, d.modules.size());
  Pipeline p;
  p.bindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  std::vector<SpirvModule> variants;
  for (const SpirvModule& m : d.modules) variants.push_back(specialize(m, d.specialization));
  p.layout = PipelineLayout(ctx, reflectPipeline(variants), options);
  const PipelineInterface& iface = p.layout.interface();
  // Stage i is module i's only entry point; a module with several would shift them.
  if (iface.stages.size() != d.modules.size()) throw Error("graphics pipeline: a module with several entry points");

  std::vector<ShaderModuleHandle> modules;
  std::vector<VkPipelineShaderStageCreateInfo> stages;
  for (size_t i = 0; i < variants.size(); ++i) {
    modules.push_back(createModule(ctx.device(), variants[i]));
    VkPipelineShaderStageCreateInfo si{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    si.stage = iface.stages[i].stage;
    si.module = modules.back();
    si.pName = iface.stages[i].entryPoint.c_str();
    stages.push_back(si);
  }

  std::vector<VkVertexInputBindingDescription> vbind;
  std::vector<VkVertexInputAttributeDescription> vattr;
  for (const StageInterface& s : iface.stages)
    if (s.stage == VK_SHADER_STAGE_VERTEX_BIT)
      for (const InterfaceVariable& v : s.inputs) {
        vbind.push_back({v.location, formatSize(v.format), VK_VERTEX_INPUT_RATE_VERTEX});
        vattr.push_back({v.location, v.location, v.format, 0});
      }
  VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  vi.vertexBindingDescriptionCount = uint32_t(vbind.size());
  vi.pVertexBindingDescriptions = vbind.data();
  vi.vertexAttributeDescriptionCount = uint32_t(vattr.size());
  vi.pVertexAttributeDescriptions = vattr.data();

  VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  vp.viewportCount = vp.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  rs.polygonMode = VK_POLYGON_MODE_FILL;
  rs.cullMode = d.cullMode;
  rs.frontFace = d.frontFace;
  rs.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  ds.depthTestEnable = d.depthTest;
  ds.depthWriteEnable = d.depthWrite;
  ds.depthCompareOp = d.depthCompare;
  std::vector<VkPipelineColorBlendAttachmentState> blends(d.colorFormats.size());
  for (auto& b : blends) {
    b.colorWriteMask = 0xF;
    if (!d.alphaBlend) continue;
    b.blendEnable = VK_TRUE;
    b.srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA;
    b.dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    b.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    b.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
  }
  VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  cb.attachmentCount = uint32_t(blends.size());
  cb.pAttachments = blends.data();
  VkDynamicState dyn[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR, VK_DYNAMIC_STATE_FRONT_FACE};
  VkPipelineDynamicStateCreateInfo dy{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
  dy.dynamicStateCount = d.dynamicFrontFace ? 3 : 2;
  dy.pDynamicStates = dyn;
  VkPipelineRenderingCreateInfo ri{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
  ri.colorAttachmentCount = uint32_t(d.colorFormats.size());
  ri.pColorAttachmentFormats = d.colorFormats.data();
  ri.depthAttachmentFormat = d.depthFormat;
  ri.pNext = &feedback.info;

  VkGraphicsPipelineCreateInfo gi{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO, &ri};
  gi.flags = captureFlags(ctx);
  gi.stageCount = uint32_t(stages.size());
  gi.pStages = stages.data();
  gi.pVertexInputState = &vi;
  gi.pInputAssemblyState = &ia;
  gi.pViewportState = &vp;
  gi.pRasterizationState = &rs;
  gi.pMultisampleState = &ms;
  gi.pDepthStencilState = &ds;
  gi.pColorBlendState = &cb;
  gi.pDynamicState = &dy;
  gi.layout = p.layout.handle();
  VkPipeline raw;
  VK_CHECK(vkCreateGraphicsPipelines(ctx.device(), ctx.pipelineCache().handle(), 1, &gi, nullptr, &raw));
  p.pipeline = PipelineHandle(ctx.device(), raw);
  feedback.created = true;
  ctx.pipelineExecutables().record(pipelineName(d.modules, d.specialization), raw);
  return p;
}

VkExtent3D groupCount(const PipelineInterface& p, uint32_t x, uint32_t y, uint32_t z) {
  if (p.stages.size() != 1 || p.stages[0].stage != VK_SHADER_STAGE_COMPUTE_BIT) throw Error("groupCount: not a compute pipeline");
  const StageInterface& st = p.stages[0];
  const uint32_t n[3] = {x, y, z};
  uint32_t g[3];
  for (int i = 0; i < 3; ++i) {
    const uint32_t size = st.localSize[i];
    if (size == 0 || size == kSpecializedSize)
      throw Error(st.module + ": groupCount needs a workgroup size written in the shader");
    g[i] = n[i] / size + (n[i] % size != 0);
  }
  return {g[0], g[1], g[2]};
}

void Pipeline::dispatch(VkCommandBuffer cb, uint32_t x, uint32_t y, uint32_t z) const {
  const VkExtent3D g = groupCount(layout.interface(), x, y, z);
  vkCmdDispatch(cb, g.width, g.height, g.depth);
}

void inParallel(const std::vector<std::function<void()>>& jobs) {
  const bool beside = PipelineCache::onBesideThread();  // the jobs count where their caller's pipelines do
  parallelFor(jobs.size(), unsigned(jobs.size()), [&](size_t i) {
    std::optional<PipelineCache::BesideThread> mark;
    if (beside) mark.emplace();
    jobs[i]();
  });
}

DescriptorSets::DescriptorSets(const Context& ctx, const PipelineLayout& layout, uint32_t copies) : copies_(copies) {
  std::map<VkDescriptorType, uint32_t> counts;
  for (const auto& b : layout.interface().bindings)
    if (!layout.isPushDescriptorSet(b.set)) counts[b.type] += layout.arrayCount(b) * copies;
  std::vector<VkDescriptorPoolSize> sizes;
  for (auto [type, n] : counts) sizes.push_back({type, n});
  if (sizes.empty()) return;
  VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pi.maxSets = layout.setCount() * copies;
  pi.poolSizeCount = uint32_t(sizes.size());
  pi.pPoolSizes = sizes.data();
  VkDescriptorPool raw;
  VK_CHECK(vkCreateDescriptorPool(ctx.device(), &pi, nullptr, &raw));
  pool_ = DescriptorPool(ctx.device(), raw);
  for (uint32_t set = 0; set < layout.setCount(); ++set) {
    if (layout.isPushDescriptorSet(set)) {
      for (uint32_t c = 0; c < copies; ++c) sets_.push_back(VK_NULL_HANDLE);
      continue;
    }
    uint32_t variable = 0;
    for (const auto& b : layout.interface().bindings)
      if (b.set == set && b.count == 0) variable = layout.arrayCount(b);
    for (uint32_t c = 0; c < copies; ++c) {
      VkDescriptorSetVariableDescriptorCountAllocateInfo vi{
          VK_STRUCTURE_TYPE_DESCRIPTOR_SET_VARIABLE_DESCRIPTOR_COUNT_ALLOCATE_INFO};
      vi.descriptorSetCount = 1;
      vi.pDescriptorCounts = &variable;
      VkDescriptorSetLayout sl = layout.setLayout(set);
      VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO, variable ? &vi : nullptr};
      ai.descriptorPool = pool_;
      ai.descriptorSetCount = 1;
      ai.pSetLayouts = &sl;
      VkDescriptorSet ds;
      VK_CHECK(vkAllocateDescriptorSets(ctx.device(), &ai, &ds));
      sets_.push_back(ds);
    }
  }
}

DescriptorWriter::DescriptorWriter(const Context& ctx, const PipelineLayout& layout, uint32_t set, VkDescriptorSet ds)
    : ctx_(ctx), layout_(layout), set_(set), ds_(ds) {}

DescriptorWriter& DescriptorWriter::buffer(uint32_t binding, VkBuffer buffer, VkDeviceSize offset, VkDeviceSize range) {
  bufferInfos_.push_back({buffer, offset, range});
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = ds_;
  w.dstBinding = binding;
  w.descriptorCount = 1;
  w.descriptorType = layout_.binding(set_, binding).type;
  w.pBufferInfo = &bufferInfos_.back();
  writes_.push_back(w);
  return *this;
}

DescriptorWriter& DescriptorWriter::image(uint32_t binding, VkImageView view, VkImageLayout layout, VkSampler sampler) {
  return images(binding, {{sampler, view, layout}});
}

DescriptorWriter& DescriptorWriter::images(uint32_t binding, const std::vector<VkDescriptorImageInfo>& infos, uint32_t first) {
  imageInfos_.push_back(infos);
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = ds_;
  w.dstBinding = binding;
  w.dstArrayElement = first;
  w.descriptorCount = uint32_t(infos.size());
  w.descriptorType = layout_.binding(set_, binding).type;
  w.pImageInfo = imageInfos_.back().data();
  writes_.push_back(w);
  return *this;
}

void DescriptorWriter::push(VkCommandBuffer cb, const Pipeline& pipeline) {
  ctx_.pushDescriptorFn()(cb, pipeline.bindPoint, pipeline.layout.handle(), set_, uint32_t(writes_.size()), writes_.data());
  clear();
}

void DescriptorWriter::clear() {
  writes_.clear();
  bufferInfos_.clear();
  imageInfos_.clear();
}

void DescriptorWriter::commit() {
  vkUpdateDescriptorSets(ctx_.device(), uint32_t(writes_.size()), writes_.data(), 0, nullptr);
  clear();
}

}  // namespace rtr::vk
