#pragma once
// The transparency pass: glTF BLEND surfaces (GpuScene::blendDraws) over the shaded opaque image, one
// instance per draw, farthest first, "over" blended by the surface's alpha (docs/gltf.md: why sorted and
// not order-independent). The opaque surfaces' depth hides them: the depth attachment where the hardware
// drew the frame (forward, hardware visibility), the compute rasteriser's per-pixel word otherwise. They
// write no depth and no visibility id. Made only for a scene with blended draws.
#include <array>
#include <optional>
#include <vector>

#include "render/environment_maps.hpp"
#include "render/gpu_scene.hpp"
#include "vk/frame_ring.hpp"
#include "vk/pipeline.hpp"
#include "vk/resources.hpp"

namespace rtr::render {

// The blended draws farthest from `eye` first (by their instance's box centre; ties keep their order).
std::vector<const BlendDraw*> farthestFirst(std::span<const BlendDraw> draws, const glm::vec3& eye);

class TransparencyPass {
 public:
  // `env`: the environment the shaded view adds (kept by the renderer while the pass lives), or null.
  TransparencyPass(const vk::Context& ctx, const GpuScene& scene, const EnvironmentMaps* env = nullptr);

  // Records the pass over `color` (left a colour attachment). `opaqueIds`: the compute rasteriser's
  // buffer (row length extent.width) when it drew the opaque surfaces, else null: `depth` holds their depth.
  void record(VkCommandBuffer cb, const vk::UploadArena::Slice& uniforms, const vk::Image& color, const vk::Image& depth,
              VkExtent2D extent, const glm::vec3& eye, VkBuffer opaqueIds);
  // Every pipeline's texture set (set 1), for the renderer to write (its one writer).
  std::vector<std::pair<const vk::PipelineLayout*, VkDescriptorSet>> textureSets() const;

 private:
  struct Variant {  // by (textured, double-sided): the vertex streams and the cull mode
    std::optional<vk::Pipeline> pipeline;
    vk::DescriptorSets textures;
  };
  const vk::Context& ctx_;
  const GpuScene& scene_;
  const EnvironmentMaps* env_;
  std::array<Variant, 4> variants_;
};

}  // namespace rtr::render
