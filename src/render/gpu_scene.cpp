#include "render/gpu_scene.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "cluster.h"
#include "core/image.hpp"
#include "scene/textures.hpp"
#include "vk/check.hpp"
#include "vk/commands.hpp"
#include "vk/context.hpp"

namespace rtr::render {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

VkFormat textureFormat(const Texture& t) {
  if (decodeChannels(t) == 1) return VK_FORMAT_R8_UNORM;
  return decodeSrgb(t) ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_R8G8B8A8_UNORM;
}

// Clusters of one draw until the scene brings its own: consecutive runs of up to CLUSTER_MAX_TRIANGLES
// triangles, a bounding sphere around the bounding box of their vertices, the cone disabled.
void appendClusters(const Mesh& m, uint32_t draw, uint32_t flags, std::vector<shader::GpuCluster>& out) {
  const uint32_t triangles = uint32_t(m.indices.size() / 3);
  for (uint32_t first = 0; first < triangles; first += CLUSTER_MAX_TRIANGLES) {
    const uint32_t count = std::min<uint32_t>(CLUSTER_MAX_TRIANGLES, triangles - first);
    Bounds b;
    for (uint32_t i = 3 * first; i < 3 * (first + count); ++i) b.extend(m.positions[m.indices[i]]);
    const glm::vec3 c = 0.5f * (b.min + b.max);
    float r = 0.0f;
    for (uint32_t i = 3 * first; i < 3 * (first + count); ++i) r = std::max(r, glm::length(m.positions[m.indices[i]] - c));
    out.push_back({glm::vec4(c, r), glm::vec4(0, 0, 1, 2), draw, first, count, flags});
  }
}

// Appends `bytes` to a staging byte vector at an offset aligned for copies, returning the offset.
size_t append(std::vector<uint8_t>& staging, const void* bytes, size_t size) {
  size_t offset = (staging.size() + 15) & ~size_t(15);
  staging.resize(offset + size);
  std::memcpy(staging.data() + offset, bytes, size);
  return offset;
}

}  // namespace

GpuScene::GpuScene(const vk::Context& ctx, const Scene& scene, MipMode mipMode) {
  const auto t0 = Clock::now();
  bounds_ = scene.bounds();

  // Which textures are sampled (scene/textures.hpp), decoded on all cores.
  const std::vector<uint32_t> used = sampledTextures(scene);  // scene texture indices, in GPU array order
  std::vector<uint32_t> gpuIndex(scene.textures.size(), NO_TEXTURE);
  for (uint32_t i = 0; i < used.size(); ++i) gpuIndex[used[i]] = i;
  const bool anyTexcoords = std::any_of(scene.meshes.begin(), scene.meshes.end(),
                                        [](const Mesh& m) { return !m.texcoords.empty() && !m.indices.empty(); });
  std::vector<TexelData> texels(used.size());
  decodeTextures(scene, used, [&](size_t i, TexelData&& t) { texels[i] = std::move(t); });
  stats_.decodeMs = msSince(t0);
  const auto t1 = Clock::now();

  // Geometry: one stream per attribute for all meshes; indices 16-bit where the mesh has <= 65536 vertices.
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> texcoords;
  std::vector<uint16_t> idx16;
  std::vector<uint32_t> idx32;
  std::vector<shader::GpuDraw> drawInfo;
  std::vector<shader::GpuCluster> clusters;
  for (const Mesh& m : scene.meshes) {
    if (m.indices.empty()) continue;
    const Material& mat = scene.materials.at(m.material);
    DrawItem d;
    d.material = m.material;
    d.indexCount = uint32_t(m.indices.size());
    d.vertexOffset = int32_t(positions.size());
    if (m.positions.size() <= 65536) {
      d.indexType = VK_INDEX_TYPE_UINT16;
      d.firstIndex = uint32_t(idx16.size());
      for (uint32_t i : m.indices) idx16.push_back(uint16_t(i));
      ++stats_.meshes16;
    } else {
      d.firstIndex = uint32_t(idx32.size());
      idx32.insert(idx32.end(), m.indices.begin(), m.indices.end());
    }
    positions.insert(positions.end(), m.positions.begin(), m.positions.end());
    normals.insert(normals.end(), m.normals.begin(), m.normals.end());
    if (anyTexcoords) {
      if (m.texcoords.empty()) texcoords.resize(positions.size(), glm::vec2(0.0f));
      else texcoords.insert(texcoords.end(), m.texcoords.begin(), m.texcoords.end());
    }
    const bool textured = !m.texcoords.empty();
    // Two-sided materials go to the alpha-tested pipeline, which does not cull (with no mask texture
    // the alpha is 1 and nothing is discarded). alphaTested is the same rule the tracer cuts out by.
    DrawKind kind = !textured                                                  ? DrawKind::Untextured
                    : alphaTested(m, mat) || (mat.flags & kMaterialDoubleSided) ? DrawKind::AlphaMasked
                                                                               : DrawKind::Opaque;
    d.id = uint32_t(drawInfo.size());
    drawInfo.push_back({d.material, d.firstIndex, uint32_t(d.vertexOffset),
                        (d.indexType == VK_INDEX_TYPE_UINT16 ? DRAW_INDEX16 : 0u) | (textured ? DRAW_TEXTURED : 0u)});
    draws_[size_t(kind)].push_back(d);
    const bool masked = kind == DrawKind::AlphaMasked && mat.texture(TextureSlot::AlphaMask) != kNoTexture;
    appendClusters(m, d.id, (kind == DrawKind::AlphaMasked ? CLUSTER_DOUBLE_SIDED : 0u) | (masked ? CLUSTER_ALPHA_MASKED : 0u),
                   clusters);
    ++stats_.meshes;
    stats_.triangles += m.triangleCount();
  }
  stats_.vertices = uint32_t(positions.size());
  if (idx16.size() % 2) idx16.push_back(0);  // keep the buffer size a multiple of 4

  std::vector<shader::GpuMaterial> materials;
  for (const Material& m : scene.materials) {
    shader::GpuMaterial g{};
    g.baseColor = glm::vec4(m.baseColor, 1.0f);
    g.emissive = glm::vec4(m.emissive, 0.0f);
    g.roughMetal = glm::vec4(m.roughness, m.metalness, 0.0f, 0.0f);
    auto tex = [&](TextureSlot s) { uint32_t t = m.texture(s); return t == kNoTexture ? NO_TEXTURE : gpuIndex[t]; };
    g.textures = glm::uvec4(tex(TextureSlot::BaseColor), tex(TextureSlot::Roughness), tex(TextureSlot::Metalness),
                            tex(TextureSlot::AlphaMask));
    g.textures2 = glm::uvec4(tex(TextureSlot::Emissive), 0, 0, 0);
    materials.push_back(g);
  }
  if (materials.empty()) materials.push_back({});

  // One staging buffer for everything; then one submission: copies, then mip generation.
  std::vector<uint8_t> staging;
  auto makeBuffer = [&](vk::Buffer& dst, const void* data, size_t size, VkBufferUsageFlags usage, const char* name) {
    if (size == 0) return size_t(0);
    dst = vk::Buffer(ctx, size, usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryUse::Device, name);
    return append(staging, data, size);
  };
  constexpr VkBufferUsageFlags kVertex = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  constexpr VkBufferUsageFlags kIndex = VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  const size_t oPos = makeBuffer(positions_, positions.data(), positions.size() * 12, kVertex, "positions");
  const size_t oNrm = makeBuffer(normals_, normals.data(), normals.size() * 12, kVertex, "normals");
  const size_t oUv = makeBuffer(texcoords_, texcoords.data(), texcoords.size() * 8, kVertex, "texcoords");
  const size_t oI16 = makeBuffer(indices16_, idx16.data(), idx16.size() * 2, kIndex, "indices16");
  const size_t oI32 = makeBuffer(indices32_, idx32.data(), idx32.size() * 4, kIndex, "indices32");
  const size_t oMat = makeBuffer(materials_, materials.data(), materials.size() * sizeof(shader::GpuMaterial),
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "materials");
  const size_t oDraw = makeBuffer(drawInfo_, drawInfo.data(), drawInfo.size() * sizeof(shader::GpuDraw),
                                  VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "draws");
  const size_t oCluster = makeBuffer(clusters_, clusters.data(), clusters.size() * sizeof(shader::GpuCluster),
                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "clusters");
  clusterCount_ = uint32_t(clusters.size());
  std::vector<size_t> texOffsets;
  for (size_t i = 0; i < used.size(); ++i) {
    const Texture& t = scene.textures[used[i]];
    textures_.emplace_back(ctx, textureDesc({texels[i].width, texels[i].height}, textureFormat(t)));
    texOffsets.push_back(append(staging, texels[i].texels.data(), texels[i].texels.size()));
  }
  texels.clear();
  stats_.textures = uint32_t(textures_.size());

  vk::Buffer stage(ctx, std::max<size_t>(staging.size(), 4), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUse::Upload, "scene staging");
  std::memcpy(stage.mapped(), staging.data(), staging.size());
  stage.flush();
  staging = {};

  MipGenerator mipGen(ctx);
  std::vector<MipViews> mipViews;  // alive until the submission has completed
  vk::GpuTimer timer(ctx, 1);
  vk::submitAndWait(ctx, [&](VkCommandBuffer cb) {
    auto copy = [&](const vk::Buffer& dst, size_t offset) {
      if (!dst.handle()) return;
      VkBufferCopy region{offset, 0, dst.size()};
      vkCmdCopyBuffer(cb, stage.handle(), dst.handle(), 1, &region);
    };
    copy(positions_, oPos);
    copy(normals_, oNrm);
    copy(texcoords_, oUv);
    copy(indices16_, oI16);
    copy(indices32_, oI32);
    copy(materials_, oMat);
    copy(drawInfo_, oDraw);
    copy(clusters_, oCluster);
    vk::memoryBarrier(cb, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_VERTEX_INPUT_BIT | VK_PIPELINE_STAGE_2_INDEX_INPUT_BIT |
                          VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_VERTEX_ATTRIBUTE_READ_BIT | VK_ACCESS_2_INDEX_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
    std::vector<vk::ImageBarrier> toDst;
    for (auto& img : textures_)
      toDst.push_back({img.handle(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                       VK_PIPELINE_STAGE_2_NONE, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE,
                       VK_ACCESS_2_TRANSFER_WRITE_BIT, 0, 1});
    if (!toDst.empty()) vk::barrier(cb, toDst);
    for (size_t i = 0; i < textures_.size(); ++i) {
      VkBufferImageCopy region{};
      region.bufferOffset = texOffsets[i];
      region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      region.imageExtent = {textures_[i].extent().width, textures_[i].extent().height, 1};
      vkCmdCopyBufferToImage(cb, stage.handle(), textures_[i].handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    }
    timer.reset(cb);
    timer.begin(cb);
    std::vector<const vk::Image*> batch;
    for (const auto& img : textures_) batch.push_back(&img);
    mipViews.push_back(mipGen.record(cb, batch, mipMode));  // all textures, one barrier per step
    timer.mark(cb, "mips");
  });
  if (!textures_.empty()) stats_.mipGpuMs = timer.results().at(0).second;
  stats_.uploadMs = msSince(t1);

  if (!textures_.empty()) {
    VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    si.magFilter = si.minFilter = VK_FILTER_LINEAR;
    si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_LINEAR;  // trilinear
    si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT;
    si.maxLod = VK_LOD_CLAMP_NONE;
    si.anisotropyEnable = VK_FALSE;  // the mip-level view must show what trilinear filtering picks
    VkSampler raw;
    VK_CHECK(vkCreateSampler(ctx.device(), &si, nullptr, &raw));
    sampler_ = vk::Sampler(ctx.device(), raw);
  }
}

std::vector<VkDescriptorImageInfo> GpuScene::textureDescriptors() const {
  std::vector<VkDescriptorImageInfo> out;
  for (const auto& t : textures_) out.push_back({sampler_, t.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
  return out;
}

}  // namespace rtr::render
