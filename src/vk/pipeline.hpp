#pragma once
// Pipelines whose layouts come from reflection: descriptor set layouts, push-constant ranges and vertex
// inputs are read from the shaders' SPIR-V (vk/reflect.hpp), never written by hand.
#include <algorithm>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <deque>
#include <vector>

#include <vulkan/vulkan.h>

#include "vk/reflect.hpp"
#include "vk/resources.hpp"

namespace rtr::vk {

class Context;

// Where compiled shaders live: $RTR_SHADER_DIR, else <exe>/../shaders, else the build tree's folder.
std::filesystem::path shaderDir();
SpirvModule loadShader(const std::string& name);  // "mosaic.comp" -> <shaderDir>/mosaic.comp.spv
// Shader hot reload: a module compiled at run time replaces the build's <name>.spv for later loadShader calls.
void setShaderOverride(const std::string& name, SpirvModule module);

// A shader's variant: the value (32 bits; a bool is 0 or 1) of its `layout(constant_id = id)` constant.
struct SpecializationConstant {
  uint32_t id;
  uint32_t value;
};
// The module with its specialization constants set and folded, and the code, inputs, outputs and
// descriptors that only the branches not taken used removed, so that reflection derives the variant's own
// layout and vertex streams. Both pipeline makers specialize through it; the driver gets the result (no
// VkSpecializationInfo). No constants: the module as it is.
SpirvModule specialize(const SpirvModule& module, const std::vector<SpecializationConstant>& constants);

struct LayoutOptions {
  // Size of each runtime-sized array binding, keyed by (set, binding). Such bindings are made
  // partially bound with a variable count, so a scene's texture count decides the size.
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> runtimeArrayCounts;
  // Sets bound with vkCmdPushDescriptorSetKHR (DescriptorWriter::push) instead of allocated sets.
  std::vector<uint32_t> pushDescriptorSets;
};

class PipelineLayout {
 public:
  PipelineLayout() = default;
  PipelineLayout(const Context& ctx, PipelineInterface interface, const LayoutOptions& options = {});
  VkPipelineLayout handle() const { return layout_; }
  VkDescriptorSetLayout setLayout(uint32_t set) const { return sets_.at(set); }
  uint32_t setCount() const { return uint32_t(sets_.size()); }
  const PipelineInterface& interface() const { return interface_; }
  const ReflectedBinding& binding(uint32_t set, uint32_t binding) const;
  // Whether the shaders use it (a specialized variant keeps only what its code reads).
  bool hasBinding(uint32_t set, uint32_t binding) const;
  uint32_t arrayCount(const ReflectedBinding& b) const;  // the count the layout was made with
  bool isPushDescriptorSet(uint32_t set) const {
    return std::find(options_.pushDescriptorSets.begin(), options_.pushDescriptorSets.end(), set) !=
           options_.pushDescriptorSets.end();
  }

 private:
  PipelineInterface interface_;
  LayoutOptions options_;
  std::vector<DescriptorSetLayout> sets_;
  PipelineLayoutHandle layout_;
};

struct Pipeline {
  PipelineLayout layout;
  PipelineHandle pipeline;
  VkPipelineBindPoint bindPoint = VK_PIPELINE_BIND_POINT_COMPUTE;

  void bind(VkCommandBuffer cb) const { vkCmdBindPipeline(cb, bindPoint, pipeline); }
  void bindSet(VkCommandBuffer cb, uint32_t set, VkDescriptorSet ds) const {
    vkCmdBindDescriptorSets(cb, bindPoint, layout.handle(), set, 1, &ds, 0, nullptr);
  }
  template <class T>
  void push(VkCommandBuffer cb, const T& data) const {
    const auto& pcs = layout.interface().pushConstants;
    if (pcs.empty() || sizeof(T) != pcs[0].offset + pcs[0].size) throwPushSizeMismatch(sizeof(T));
    vkCmdPushConstants(cb, layout.handle(), pcs[0].stages, 0, sizeof(T), &data);
  }
  void throwPushSizeMismatch(size_t size) const;
  // vkCmdDispatch of the workgroups that cover x × y × z invocations (groupCount).
  void dispatch(VkCommandBuffer cb, uint32_t x, uint32_t y = 1, uint32_t z = 1) const;
};

// Workgroups that cover x × y × z invocations, one per item, with the compute shader's reflected
// workgroup size: the one rounding every dispatch uses, so no size is written twice.
VkExtent3D groupCount(const PipelineInterface& p, uint32_t x, uint32_t y = 1, uint32_t z = 1);

Pipeline makeComputePipeline(const Context& ctx, const SpirvModule& shader, const LayoutOptions& options = {},
                             const std::vector<SpecializationConstant>& specialization = {});

struct GraphicsDesc {
  std::vector<SpirvModule> modules;  // vertex + fragment
  // Vertex inputs are reflected: each vertex-shader input location reads its own tightly packed stream,
  // bound at the binding number equal to its location.
  VkCullModeFlags cullMode = VK_CULL_MODE_BACK_BIT;
  VkFrontFace frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  bool dynamicFrontFace = false;  // set by vkCmdSetFrontFace before drawing (mirrored instances)
  bool depthTest = true, depthWrite = true;
  bool alphaBlend = false;  // colour = src.a * src + (1 - src.a) * dst (overlays such as the viewer's panel)
  VkCompareOp depthCompare = VK_COMPARE_OP_LESS;
  std::vector<VkFormat> colorFormats;
  VkFormat depthFormat = VK_FORMAT_UNDEFINED;
  std::vector<SpecializationConstant> specialization;
};
Pipeline makeGraphicsPipeline(const Context& ctx, const GraphicsDesc& desc, const LayoutOptions& options = {});

// Runs the jobs at once, each on a thread (parallelFor), waits for all and rethrows the first job's
// failure. For making pipelines in parallel: a driver compiles each on the calling thread, and creation
// is thread-safe (the VkPipelineCache is internally synchronized: made without EXTERNALLY_SYNCHRONIZED).
void inParallel(const std::vector<std::function<void()>>& jobs);

// Descriptor sets for one pipeline layout, `copies` of each set (e.g. one per frame in flight).
class DescriptorSets {
 public:
  DescriptorSets() = default;
  DescriptorSets(const Context& ctx, const PipelineLayout& layout, uint32_t copies);
  VkDescriptorSet get(uint32_t set, uint32_t copy = 0) const { return sets_.at(set * copies_ + copy); }

 private:
  DescriptorPool pool_;
  uint32_t copies_ = 0;
  std::vector<VkDescriptorSet> sets_;
};

// Fills a descriptor set; each binding's descriptor type is looked up in the reflected layout.
class DescriptorWriter {
 public:
  DescriptorWriter(const Context& ctx, const PipelineLayout& layout, uint32_t set, VkDescriptorSet ds);
  DescriptorWriter& buffer(uint32_t binding, VkBuffer buffer, VkDeviceSize offset = 0, VkDeviceSize range = VK_WHOLE_SIZE);
  DescriptorWriter& image(uint32_t binding, VkImageView view, VkImageLayout layout, VkSampler sampler = VK_NULL_HANDLE);
  // Elements first, first + 1, ... of an array binding.
  DescriptorWriter& images(uint32_t binding, const std::vector<VkDescriptorImageInfo>& infos, uint32_t first = 0);
  void commit();  // updates an allocated set
  // Records the writes as push descriptors for `set` of `pipeline` (its layout must list the set in
  // LayoutOptions::pushDescriptorSets); the writer was made with ds = VK_NULL_HANDLE.
  void push(VkCommandBuffer cb, const struct Pipeline& pipeline);

 private:
  const Context& ctx_;
  const PipelineLayout& layout_;
  uint32_t set_;
  VkDescriptorSet ds_;
  void clear();
  // Deques: the writes point into them, and a deque keeps its elements in place as it grows.
  std::deque<std::vector<VkDescriptorImageInfo>> imageInfos_;
  std::deque<VkDescriptorBufferInfo> bufferInfos_;
  std::vector<VkWriteDescriptorSet> writes_;
};

}  // namespace rtr::vk
