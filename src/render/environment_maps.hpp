#pragma once
// An environment prepared for shading by the split-sum approximation, in compute (docs/environment.md):
// the equirectangular map onto a cube with its mip chain (the source), a GGX-prefiltered specular cube
// with one roughness per mip, diffuse irradiance as 9 spherical-harmonic coefficients, and the split-sum
// BRDF table. Built in one submission when made; each pass timed. No window, no scene.
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "scene/environment.hpp"
#include "vk/resources.hpp"

namespace rtr::vk {
class Context;
class DescriptorWriter;
class PipelineLayout;
}  // namespace rtr::vk

namespace rtr::render {

struct EnvironmentMapSettings {
  uint32_t sourceSize = 0;      // source cube face; 0: a quarter of the map's width, 32..512, a power of two
  uint32_t specularSize = 128;  // level 0 of the specular cube (roughness 0)
  uint32_t specularLevels = 5;  // roughness (level / (levels - 1)); the last level is at least 8²
  uint32_t samples = 512;       // half vectors per texel of specular level 1 where it is importance-sampled (a lobe
                                // narrower than two texels of a 64²-a-face level: more than 5 levels), doubling
                                // each level down; level 0: one; the other levels are summed over source texels
  uint32_t lutSize = 64;
  uint32_t lutSamples = 256;
};

class EnvironmentMaps {
 public:
  // Throws rtr::Error for an empty environment or a device that cannot filter 32-bit float images.
  EnvironmentMaps(const vk::Context& ctx, const Environment& env, const EnvironmentMapSettings& settings = {});

  const vk::Image& map() const { return map_; }            // RGBA32F, the equirectangular map (the mirror reads it)
  const vk::Image& source() const { return source_; }      // RGBA32F cube with mips
  const vk::Image& specular() const { return specular_; }  // RGBA16F cube, roughness per mip
  // RGBA16F (A, B, C, 0), lutSize wide and 2 lutSize high: Beckmann's rows, then GGX's (envLutUv).
  const vk::Image& brdfLut() const { return lut_; }
  VkBuffer sh() const { return sh_.handle(); }    // 9 vec4: rgb coefficients
  VkSampler sampler() const { return sampler_; }  // linear, mips, clamped
  const EnvironmentMapSettings& settings() const { return settings_; }
  float rotation() const { return rotation_; }  // the map's about +y, radians (the cubes have it applied)
  // GPU milliseconds of each pass of the build, in order: cube, source mips, specular, sh, lut.
  const std::vector<std::pair<std::string, double>>& times() const { return times_; }

 private:
  EnvironmentMapSettings settings_;
  float rotation_ = 0.0f;
  vk::Image map_, source_, specular_, lut_;
  vk::Buffer sh_;
  vk::Sampler sampler_;
  std::vector<std::pair<std::string, double>> times_;
};

// Writes `env`'s maps to set 0, bindings 20-24 (shaders/env_light.glsl), each where `layout` has it
// (specialization drops what a variant does not read); nothing without an environment.
void writeEnvironment(vk::DescriptorWriter& w, const vk::PipelineLayout& layout, const EnvironmentMaps* env);

}  // namespace rtr::render
