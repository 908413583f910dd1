#include "render/environment_maps.hpp"

#include <algorithm>
#include <bit>
#include <cstring>

#include "core/error.hpp"
#include "env_prefilter.h"
#include "vk/check.hpp"
#include "vk/commands.hpp"
#include "vk/context.hpp"
#include "vk/pipeline.hpp"

namespace rtr::render {

namespace {

constexpr VkFormat kSourceFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkPipelineStageFlags2 kCompute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
constexpr uint32_t kShMaxFace = 32;   // the spherical harmonics read the first source level this small
constexpr uint32_t kSumMinFace = 16;  // env_specular_sum.comp: its coarse level, and the least fine one
constexpr uint32_t kSumMaxFace = 64;  // the finest level it reads (its cost: the fine texels near each lobe)
// How far from a texel's direction, in the lobe's half widths, the sum reads the fine level. Measured on
// a sky whose sun is 10^4 times the sky (roughness 0.25, 64² fine level): 1 leaves the tail's coarse
// texels 15 % off next to the sun, 2 and more are within 3.3 % as the sum over every fine texel is.
constexpr float kNearLobes = 4.0f;

// The face size of the source level that the specular level of `roughness` is summed over
// (env_specular_sum.comp) near each texel's direction, or 0 where it is importance-sampled: the smallest
// level on which GGX's reflected lobe (half its peak at about 1.29 alpha radians from the centre) is at
// least two texels (2 / face radians at a face's centre) wide, if that is at most kSumMaxFace a side; the
// source's level 0 where the source is smaller (and at least the coarse level).
uint32_t sumFace(float roughness, uint32_t sourceSize) {
  const float alpha = std::max(roughness * roughness, shader::BRDF_ALPHA_MIN);
  const uint32_t face = std::max(std::bit_ceil(uint32_t(std::ceil(4.0f / (1.29f * alpha)))), kSumMinFace);
  return face <= kSumMaxFace && sourceSize >= kSumMinFace ? std::min(face, sourceSize) : 0;
}

void checkDevice(const vk::Context& ctx) {
  VkFormatProperties p;
  vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), kSourceFormat, &p);
  const VkFormatFeatureFlags need = VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT | VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT;
  if ((p.optimalTilingFeatures & need) != need)
    throw Error("environment lighting needs a device that filters and stores 32-bit float RGBA images");
}

vk::Sampler makeEnvSampler(const vk::Context& ctx) {
  VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  si.magFilter = si.minFilter = VK_FILTER_LINEAR;
  si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_LINEAR;
  si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  si.maxLod = VK_LOD_CLAMP_NONE;
  VkSampler raw;
  VK_CHECK(vkCreateSampler(ctx.device(), &si, nullptr, &raw));
  return vk::Sampler(ctx.device(), raw);
}

}  // namespace

EnvironmentMaps::EnvironmentMaps(const vk::Context& ctx, const Environment& env, const EnvironmentMapSettings& settings)
    : settings_(settings), rotation_(env.rotation()) {
  if (env.empty()) throw Error("EnvironmentMaps: no environment");
  checkDevice(ctx);
  const ImageF& map = env.map();
  EnvironmentMapSettings& s = settings_;
  if (s.sourceSize == 0) s.sourceSize = std::clamp(std::bit_floor(std::max(map.width / 4, 1u)), 32u, 512u);
  s.specularSize = std::max(std::bit_floor(s.specularSize), 8u);
  // The last level at least 8 texels a side: a coarser texel spans more than the lobe it stands for.
  s.specularLevels = std::clamp(s.specularLevels, 2u, uint32_t(std::bit_width(s.specularSize)) - 3u);
  s.samples = std::max(s.samples, 1u);
  const uint32_t sourceLevels = uint32_t(std::bit_width(s.sourceSize));

  // Copy source: the maps can be read back (tests, the report's error figures).
  constexpr VkImageUsageFlags kRw = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  map_ = vk::Image(ctx, {{map.width, map.height},
                         kSourceFormat,
                         1,
                         VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                         0,
                         0,
                         "environment map"});
  source_ =
      vk::Image(ctx, {{s.sourceSize, s.sourceSize}, kSourceFormat, sourceLevels, kRw, 0, 0, "environment source cube", true});
  specular_ = vk::Image(ctx, {{s.specularSize, s.specularSize},
                              VK_FORMAT_R16G16B16A16_SFLOAT,
                              s.specularLevels,
                              kRw,
                              0,
                              0,
                              "environment specular cube",
                              true});
  lut_ = vk::Image(ctx, {{s.lutSize, 2 * s.lutSize}, VK_FORMAT_R16G16B16A16_SFLOAT, 1, kRw, 0, 0, "split-sum table"});
  sh_ = vk::Buffer(ctx, 9 * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                   vk::MemoryUse::Device, "environment sh");
  sampler_ = makeEnvSampler(ctx);

  const size_t bytes = map.pixels.size() * sizeof(glm::vec4);
  vk::Buffer stage(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUse::Upload, "environment staging");
  std::memcpy(stage.mapped(), map.pixels.data(), bytes);
  stage.flush();

  const vk::LayoutOptions push{.pushDescriptorSets = {0}};
  const vk::Pipeline toCube = vk::makeComputePipeline(ctx, vk::loadShader("env_to_cube.comp"), push);
  const vk::Pipeline down = vk::makeComputePipeline(ctx, vk::loadShader("env_cube_down.comp"), push);
  const vk::Pipeline spec = vk::makeComputePipeline(ctx, vk::loadShader("env_specular.comp"), push);
  const vk::Pipeline specSum = vk::makeComputePipeline(ctx, vk::loadShader("env_specular_sum.comp"), push);
  const vk::Pipeline shPass = vk::makeComputePipeline(ctx, vk::loadShader("env_sh.comp"), push);
  const vk::Pipeline lut = vk::makeComputePipeline(ctx, vk::loadShader("env_brdf_lut.comp"), push);

  // Per-level storage views (a cube's faces as an array) and the faces of every source level, sampled.
  std::vector<vk::ImageView> sourceLevelViews, specularLevelViews;
  for (uint32_t l = 0; l < sourceLevels; ++l)
    sourceLevelViews.push_back(source_.createView(kSourceFormat, l, 1, VK_IMAGE_USAGE_STORAGE_BIT, true));
  for (uint32_t l = 0; l < s.specularLevels; ++l)
    specularLevelViews.push_back(specular_.createView(VK_FORMAT_R16G16B16A16_SFLOAT, l, 1, VK_IMAGE_USAGE_STORAGE_BIT, true));
  const vk::ImageView sourceFaces = source_.createView(kSourceFormat, 0, sourceLevels, VK_IMAGE_USAGE_SAMPLED_BIT, true);
  const vk::ImageView sourceCube = source_.createView(kSourceFormat, 0, sourceLevels, VK_IMAGE_USAGE_SAMPLED_BIT);

  vk::GpuTimer timer(ctx, 8);
  vk::submitAndWait(ctx, [&](VkCommandBuffer cb) {
    timer.reset(cb);
    vk::require(cb, map_.tracked(), vk::Use::CopyDst, VK_PIPELINE_STAGE_2_COPY_BIT, true);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {map.width, map.height, 1};
    vkCmdCopyBufferToImage(cb, stage.handle(), map_.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    vk::require(cb, {{map_.tracked(), vk::Use::Sampled, kCompute}, {source_.tracked(), vk::Use::Storage, kCompute, true}});
    timer.begin(cb);

    shader::EnvPush pc{};
    pc.size = s.sourceSize;
    pc.rotation = env.rotation();
    toCube.bind(cb);
    vk::DescriptorWriter(ctx, toCube.layout, 0, VK_NULL_HANDLE)
        .image(0, map_.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL)
        .image(1, sourceLevelViews[0], VK_IMAGE_LAYOUT_GENERAL)
        .push(cb, toCube);
    toCube.push(cb, pc);
    toCube.dispatch(cb, pc.size, pc.size, 6);
    timer.mark(cb, "env cube");

    down.bind(cb);
    for (uint32_t l = 1; l < sourceLevels; ++l) {                       // each level reads the one just written
      vk::bufferBarrier(cb, vk::kComputeWrite, vk::kComputeReadWrite);  // a global barrier: images in GENERAL too
      pc.size = s.sourceSize >> l;
      vk::DescriptorWriter(ctx, down.layout, 0, VK_NULL_HANDLE)
          .image(0, sourceLevelViews[l - 1], VK_IMAGE_LAYOUT_GENERAL)
          .image(1, sourceLevelViews[l], VK_IMAGE_LAYOUT_GENERAL)
          .push(cb, down);
      down.push(cb, pc);
      down.dispatch(cb, pc.size, pc.size, 6);
    }
    timer.mark(cb, "env mips");

    vk::require(cb, {{source_.tracked(), vk::Use::Sampled, kCompute},
                     {specular_.tracked(), vk::Use::Storage, kCompute, true},
                     {lut_.tracked(), vk::Use::Storage, kCompute, true}});
    pc.srcLevels = sourceLevels;
    pc.srcTexelSolidAngle = 4.0f * shader::BRDF_PI / (6.0f * float(s.sourceSize) * float(s.sourceSize));
    for (uint32_t l = 0; l < s.specularLevels; ++l) {
      pc.size = s.specularSize >> l;
      pc.roughness = float(l) / float(s.specularLevels - 1);
      pc.srcSize = sumFace(pc.roughness, s.sourceSize);
      pc.nearAngle = kNearLobes * 1.29f * std::max(pc.roughness * pc.roughness, shader::BRDF_ALPHA_MIN);
      const vk::Pipeline& p = pc.srcSize ? specSum : spec;
      p.bind(cb);
      vk::DescriptorWriter w(ctx, p.layout, 0, VK_NULL_HANDLE);
      if (pc.srcSize) {  // summed over source texels
        pc.level = uint32_t(std::countr_zero(s.sourceSize / pc.srcSize));
        w.image(0, sourceFaces, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
      } else {
        // Roughness 0's lobe is narrower than its texel: one sample. Other narrow lobes: half vectors
        // drawn from D, twice as many each level down (4 times fewer texels, wider lobes).
        pc.samples = l == 0 ? 1u : s.samples << (l - 1);
        w.image(0, sourceCube, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, sampler_);
      }
      w.image(1, specularLevelViews[l], VK_IMAGE_LAYOUT_GENERAL).push(cb, p);
      p.push(cb, pc);
      p.dispatch(cb, pc.size, pc.size, pc.srcSize ? 6 * ENV_SUM_SLICES : 6);  // the sum: slices of a texel in z
    }
    timer.mark(cb, "env specular");

    pc.level = 0;
    while ((s.sourceSize >> pc.level) > kShMaxFace) ++pc.level;
    pc.size = s.sourceSize >> pc.level;
    shPass.bind(cb);
    vk::DescriptorWriter(ctx, shPass.layout, 0, VK_NULL_HANDLE)
        .image(0, sourceFaces, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL)
        .buffer(1, sh_.handle())
        .push(cb, shPass);
    shPass.push(cb, pc);
    vkCmdDispatch(cb, 1, 1, 1);  // one workgroup: a fixed order of sums
    timer.mark(cb, "env sh");

    pc.size = s.lutSize;
    pc.samples = s.lutSamples;
    lut.bind(cb);
    vk::DescriptorWriter(ctx, lut.layout, 0, VK_NULL_HANDLE).image(0, lut_.view(), VK_IMAGE_LAYOUT_GENERAL).push(cb, lut);
    lut.push(cb, pc);
    lut.dispatch(cb, pc.size, 2 * pc.size);
    timer.mark(cb, "env lut");

    // Ready for shading in compute or fragment shaders.
    constexpr VkPipelineStageFlags2 kShading = kCompute | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
    vk::require(cb, {{map_.tracked(), vk::Use::Sampled, kShading},
                     {source_.tracked(), vk::Use::Sampled, kShading},
                     {specular_.tracked(), vk::Use::Sampled, kShading},
                     {lut_.tracked(), vk::Use::Sampled, kShading}});
    vk::bufferBarrier(cb, vk::kComputeWrite, vk::kComputeRead | vk::kFragmentRead);  // the sh buffer
  });
  times_ = timer.results();
}

}  // namespace rtr::render

namespace rtr::render {

void writeEnvironment(vk::DescriptorWriter& w, const vk::PipelineLayout& layout, const EnvironmentMaps* env) {
  if (!env) return;
  const auto has = [&layout](uint32_t binding) { return layout.hasBinding(0, binding); };
  constexpr VkImageLayout kRead = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  if (has(20)) w.image(20, env->specular().view(), kRead, env->sampler());
  if (has(21)) w.image(21, env->brdfLut().view(), kRead, env->sampler());
  if (has(22)) w.buffer(22, env->sh());
  if (has(23)) w.image(23, env->source().view(), kRead, env->sampler());
  if (has(24)) w.image(24, env->map().view(), kRead);
}

}  // namespace rtr::render
