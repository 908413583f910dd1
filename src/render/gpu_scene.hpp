#pragma once
// A scene on the GPU: vertex streams, index buffers (16-bit where a mesh allows; both also readable as
// storage buffers by the visibility path's shading pass), the material and draw buffers and the textures that some drawn material uses (decoded on several threads, uploaded through one
// staging buffer, mips generated on the GPU). Nothing the scene does not use is created.
#include <array>
#include <vector>

#include "frame.h"
#include "render/mips.hpp"
#include "scene/scene.hpp"
#include "vk/resources.hpp"

namespace rtr::vk { class Context; }

namespace rtr::render {

// Which scene pipeline draws a mesh: the textured opaque one, the one without texcoords, or the
// alpha-masked, double-sided one.
enum class DrawKind { Opaque, Untextured, AlphaMasked, Count };
constexpr size_t kDrawKindCount = size_t(DrawKind::Count);

struct DrawItem {
  uint32_t material = 0;
  uint32_t indexCount = 0;
  uint32_t firstIndex = 0;   // in the index buffer of its type
  int32_t vertexOffset = 0;
  VkIndexType indexType = VK_INDEX_TYPE_UINT32;
  uint32_t id = 0;           // index of its GpuDraw in drawInfo() (visibility path)
};

struct GpuSceneStats {
  uint32_t meshes = 0, triangles = 0, vertices = 0, textures = 0, meshes16 = 0;
  double decodeMs = 0, uploadMs = 0, mipGpuMs = 0;
};

class GpuScene {
 public:
  GpuScene(const vk::Context& ctx, const Scene& scene, MipMode mips);

  const std::vector<DrawItem>& draws(DrawKind k) const { return draws_[size_t(k)]; }
  bool hasDraws(DrawKind k) const { return !draws_[size_t(k)].empty(); }
  VkBuffer positions() const { return positions_.handle(); }
  VkBuffer normals() const { return normals_.handle(); }
  VkBuffer texcoords() const { return texcoords_.handle(); }  // null when no mesh has texcoords
  VkBuffer indices16() const { return indices16_.handle(); }
  VkBuffer indices32() const { return indices32_.handle(); }
  VkBuffer materials() const { return materials_.handle(); }
  VkBuffer drawInfo() const { return drawInfo_.handle(); }  // GpuDraw per draw, for shading in compute
  VkBuffer clusters() const { return clusters_.handle(); }  // GpuCluster (cluster.h), draw by draw
  uint32_t clusterCount() const { return clusterCount_; }
  uint32_t textureCount() const { return uint32_t(textures_.size()); }
  std::vector<VkDescriptorImageInfo> textureDescriptors() const;
  const Bounds& bounds() const { return bounds_; }
  const GpuSceneStats& stats() const { return stats_; }

 private:
  std::array<std::vector<DrawItem>, kDrawKindCount> draws_;
  vk::Buffer positions_, normals_, texcoords_, indices16_, indices32_, materials_, drawInfo_, clusters_;
  uint32_t clusterCount_ = 0;
  std::vector<vk::Image> textures_;
  vk::Sampler sampler_;
  Bounds bounds_;
  GpuSceneStats stats_;
};

}  // namespace rtr::render
