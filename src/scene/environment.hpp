#pragma once
// Light from an environment: an equirectangular radiance map (a file or the generated daylight sky),
// with what both renderers need of it on the CPU side — lookups, importance sampling by luminance for
// the tracer's Monte Carlo, and diffuse irradiance as spherical harmonics (the CPU reference of the
// GPU's projection). The mapping is shaders/shared/environment.h's. No GPU here. docs/environment.md.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/image.hpp"

namespace rtr {

// Where the light comes from: `--env FILE|sky|none`, `--env-intensity K`, `--env-rotation DEG`.
struct EnvironmentSettings {
  std::string source = "none";  // "none", "sky", or an .hdr/.exr file
  float intensity = 1.0f;
  float rotationDeg = 0.0f;
};

// The daylight sky: single scattering by air (Rayleigh) and haze (Mie) in a spherical, exponentially
// thinning atmosphere; the sun's light after the atmosphere sits in the one texel of its centre (its
// 0.53° disk is smaller than a texel at usual sizes). Linear radiance, scaled so that the sky and the sun
// together give a horizontal white Lambertian surface a radiance of 1; below the horizon, grey ground.
struct SkySettings {
  uint32_t width = 512, height = 256;
  float sunElevationDeg = 35.0f;
  float sunAzimuthDeg = 30.0f;  // from -z towards +x
  float haze = 1.0f;            // multiplies the Mie (aerosol) density
};
ImageF makeSky(const SkySettings& s);
glm::vec3 skySunDirection(const SkySettings& s);  // unit, from the ground towards the sun

struct EnvSample {
  glm::vec3 direction;  // unit, world space, towards where the light comes from
  glm::vec3 radiance;   // as texel(direction)
  float pdf = 0.0f;     // per unit solid angle
};

class Environment {
 public:
  Environment() = default;  // none: black, nothing to sample
  // `radiance`: equirectangular, linear, top row = zenith. Throws rtr::Error on an empty or non-finite map.
  Environment(ImageF radiance, float intensity, float rotationRad);
  // Reads settings.source (a file: .hdr or .exr), or makes the sky. Throws rtr::Error naming the file.
  static Environment load(const EnvironmentSettings& settings);

  bool empty() const { return map_.pixels.empty(); }
  const ImageF& map() const { return map_; }  // intensity applied
  float rotation() const { return rotation_; }

  // Bilinear radiance towards `direction` (unit, world space).
  glm::vec3 lookup(const glm::vec3& direction) const;
  // The radiance of the texel that holds `direction`: the map as a piecewise-constant function, the one
  // the tracer integrates (and the SH projection). Sampled in exact proportion to luminance, a texel's
  // radiance / pdf is constant within it, so a sun in one texel adds no variance of its own.
  glm::vec3 texel(const glm::vec3& direction) const;
  // A direction drawn in proportion to luminance (per unit solid angle) from two uniform numbers in [0,1).
  EnvSample sample(glm::vec2 u) const;
  // The density sample() draws `direction` with, per unit solid angle.
  float pdf(const glm::vec3& direction) const;
  // Radiance projected onto the real SH basis of bands 0-2 (environment.h's order), integrated per texel.
  const std::array<glm::vec3, 9>& sh() const { return sh_; }
  // Diffuse irradiance at normal n from the SH coefficients (what the GPU evaluates).
  glm::vec3 irradianceSh(const glm::vec3& n) const;

 private:
  void buildSampling();
  ImageF map_;
  float rotation_ = 0.0f;
  // Sampling: one alias table over texels, weights luminance × sin(theta) (the texel's solid angle).
  std::vector<float> prob_;      // the probability of keeping texel i in its slot
  std::vector<uint32_t> alias_;  // the texel taken instead
  std::vector<float> density_;   // texel i's share of the total weight, times the texel count
  std::array<glm::vec3, 9> sh_{};
};

}  // namespace rtr
