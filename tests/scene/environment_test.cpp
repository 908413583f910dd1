// The environment's CPU side: the shared equirectangular mapping, importance sampling (its density
// against what it draws), the SH irradiance against direct integration, the generated sky's physics,
// and .hdr/.exr reading.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "core/error.hpp"
#include "core/image.hpp"
#include "environment.h"
#include "scene/environment.hpp"

namespace rtr {
namespace {

constexpr float kPi = 3.14159265358979f;

ImageF constantMap(uint32_t w, uint32_t h, glm::vec3 c) {
  return {w, h, std::vector<glm::vec4>(size_t(w) * h, glm::vec4(c, 1.0f))};
}

// A map bright in one small patch (a "sun") and dim elsewhere, with colour that varies with direction.
ImageF patchMap(uint32_t w, uint32_t h) {
  ImageF m = constantMap(w, h, glm::vec3(0.1f));
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) m.at(x, y) = glm::vec4(0.05f + 0.1f * float(x) / w, 0.1f, 0.2f * float(y) / h, 1.0f);
  for (uint32_t y = h / 4; y < h / 4 + 3; ++y)
    for (uint32_t x = w / 3; x < w / 3 + 3; ++x) m.at(x, y) = glm::vec4(500.0f, 400.0f, 300.0f, 1.0f);
  return m;
}

TEST(Environment, MappingRoundTripsAndFacesTheDefaultView) {
  for (float rot : {0.0f, 0.7f, -2.0f}) {
    for (float u = 0.05f; u < 1.0f; u += 0.1f)
      for (float v = 0.05f; v < 1.0f; v += 0.1f) {
        const glm::vec2 uv = shader::envDirToUv(shader::envUvToDir({u, v}, rot), rot);
        EXPECT_NEAR(uv.x, u, 1e-5f);
        EXPECT_NEAR(uv.y, v, 1e-5f);
      }
  }
  // u = 0.5 looks down -z, u = 0.75 down +x, v = 0 is the zenith.
  const glm::vec3 fwd = shader::envUvToDir({0.5f, 0.5f}, 0.0f), right = shader::envUvToDir({0.75f, 0.5f}, 0.0f);
  EXPECT_NEAR(fwd.z, -1.0f, 1e-6f);
  EXPECT_NEAR(right.x, 1.0f, 1e-6f);
  EXPECT_NEAR(shader::envUvToDir({0.3f, 0.0f}, 0.0f).y, 1.0f, 1e-6f);
  // A rotation of +90° brings what was down +x... to -z: the environment turns, the view does not.
  EXPECT_NEAR(shader::envDirToUv({0.0f, 0.0f, -1.0f}, kPi / 2).x, 0.25f, 1e-5f);
}

TEST(Environment, ConstantRadianceGivesIrradiancePiEverywhere) {
  const Environment env(constantMap(64, 32, glm::vec3(1.0f, 0.5f, 2.0f)), 1.0f, 0.3f);
  for (const glm::vec3 n : {glm::vec3(0, 1, 0), glm::vec3(0, -1, 0), glm::normalize(glm::vec3(1, 2, -3))}) {
    const glm::vec3 e = env.irradianceSh(n);
    EXPECT_NEAR(e.r, kPi * 1.0f, 2e-3f);
    EXPECT_NEAR(e.g, kPi * 0.5f, 2e-3f);
    EXPECT_NEAR(e.b, kPi * 2.0f, 4e-3f);
  }
}

TEST(Environment, IntensityScalesTheMap) {
  const Environment env(constantMap(16, 8, glm::vec3(0.5f)), 3.0f, 0.0f);
  EXPECT_FLOAT_EQ(env.lookup({0, 0, -1}).r, 1.5f);
  EXPECT_THROW(Environment(constantMap(16, 8, glm::vec3(-1.0f)), 1.0f, 0.0f), Error);
  EXPECT_THROW(Environment(constantMap(16, 8, glm::vec3(NAN)), 1.0f, 0.0f), Error);
}

// The density sample() reports is the one pdf() gives for its direction, draws follow it (a histogram
// of draws against the density's integral per region), and L/pdf estimates the map's integral.
TEST(Environment, SamplingFollowsItsDensityAndIsUnbiased) {
  const Environment env(patchMap(128, 64), 1.0f, 0.4f);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const int n = 200000;
  glm::dvec3 estimate(0.0);
  int upper = 0, differ = 0;
  for (int i = 0; i < n; ++i) {
    const EnvSample s = env.sample({uni(rng), uni(rng)});
    ASSERT_GT(s.pdf, 0.0f);
    // Equal but where rounding moves a draw on a texel's edge to its neighbour.
    differ += std::abs(std::log(s.pdf) - std::log(env.pdf(s.direction))) > 1e-3f;
    ASSERT_NEAR(glm::length(s.direction), 1.0f, 1e-5f);
    estimate += glm::dvec3(s.radiance) / double(s.pdf);
    upper += s.direction.y > 0.0f;
  }
  estimate /= n;
  EXPECT_LT(differ, n / 1000);
  // The exact integral of the (bilinear) map over the sphere, by dense quadrature.
  glm::dvec3 exact(0.0);
  const int qw = 1024, qh = 512;
  for (int y = 0; y < qh; ++y)
    for (int x = 0; x < qw; ++x) {
      const float v = (y + 0.5f) / qh;
      const glm::vec3 d = shader::envUvToDir({(x + 0.5f) / qw, v}, 0.0f);
      exact += glm::dvec3(env.lookup(d)) * double(2 * kPi / qw * kPi / qh * std::sin(v * kPi));
    }
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(estimate[c] / exact[c], 1.0, 0.02) << c;
  // The patch is in the upper half (row h/4): most draws go there.
  EXPECT_GT(upper, n * 0.8);
}

TEST(Environment, ShIrradianceMatchesDirectIntegrationOfASmoothMap) {
  ImageF m = constantMap(64, 32, glm::vec3(0.0f));
  for (uint32_t y = 0; y < 32; ++y)
    for (uint32_t x = 0; x < 64; ++x) {
      const glm::vec3 d = shader::envUvToDir({(x + 0.5f) / 64, (y + 0.5f) / 32}, 0.0f);
      m.at(x, y) = glm::vec4(1.0f + d.y, 1.0f + 0.5f * d.x + 0.4f * d.x * d.z, 1.0f - 0.3f * d.z + 0.3f * d.x * d.y,
                             1.0f);  // bands 0-2: exact in SH
    }
  const Environment env(std::move(m), 1.0f, 0.0f);
  for (const glm::vec3 n : {glm::vec3(0, 1, 0), glm::vec3(1, 0, 0), glm::normalize(glm::vec3(-1, -1, 2))}) {
    glm::dvec3 direct(0.0);
    const int qw = 256, qh = 128;
    for (int y = 0; y < qh; ++y)
      for (int x = 0; x < qw; ++x) {
        const float v = (y + 0.5f) / qh;
        const glm::vec3 d = shader::envUvToDir({(x + 0.5f) / qw, v}, 0.0f);
        direct +=
            glm::dvec3(env.lookup(d)) * double(std::max(glm::dot(d, n), 0.0f) * 2 * kPi / qw * kPi / qh * std::sin(v * kPi));
      }
    const glm::vec3 sh = env.irradianceSh(n);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sh[c], direct[c], 0.02 * direct[c]) << c;
  }
}

TEST(Environment, SkyIsPhysicallyPlausible) {
  SkySettings s;
  s.width = 128;
  s.height = 64;
  const ImageF sky = makeSky(s);
  float maxSky = 0.0f, sun = 0.0f;
  for (uint32_t y = 0; y < sky.height; ++y)
    for (uint32_t x = 0; x < sky.width; ++x) {
      const glm::vec4 p = sky.at(x, y);
      for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(p[c]) && p[c] >= 0.0f);
      sun = std::max(sun, p.g);
    }
  const glm::vec2 suv = shader::envDirToUv(skySunDirection(s), 0.0f);
  const uint32_t sx = uint32_t(suv.x * sky.width), sy = uint32_t(suv.y * sky.height);
  EXPECT_EQ(sky.at(sx, sy).g, sun);  // the brightest texel holds the sun
  for (uint32_t y = 0; y < sky.height / 2; ++y)
    for (uint32_t x = 0; x < sky.width; ++x)
      if (x != sx || y != sy) maxSky = std::max(maxSky, sky.at(x, y).g);
  EXPECT_GT(sun, 100.0f * maxSky);
  // Rayleigh: the zenith away from the sun is blue (blue over red), more so than near the horizon.
  const uint32_t ax = (sx + sky.width / 2) % sky.width;
  const glm::vec4 zen = sky.at(ax, 2), hor = sky.at(ax, sky.height / 2 - 1);
  EXPECT_GT(zen.b / zen.r, 1.5f);
  EXPECT_GT(zen.b / zen.r, hor.b / hor.r);
  // Normalised: a white horizontal surface sees irradiance pi (luminance; summed texel by texel).
  double irr = 0.0;
  for (uint32_t y = 0; y < sky.height / 2; ++y)
    for (uint32_t x = 0; x < sky.width; ++x) {
      const glm::vec3 d = shader::envUvToDir({(x + 0.5f) / sky.width, (y + 0.5f) / sky.height}, 0.0f);
      const double omega =
          2 * kPi / sky.width * (std::cos(double(y) / sky.height * kPi) - std::cos(double(y + 1) / sky.height * kPi));
      irr += glm::dot(glm::vec3(sky.at(x, y)), glm::vec3(0.2126f, 0.7152f, 0.0722f)) * d.y * omega;
    }
  EXPECT_NEAR(irr, kPi, 0.02 * kPi);
}

TEST(Environment, ReadsHdrAndExrItWrote) {
  const auto dir = std::filesystem::temp_directory_path() / ("rtr_env_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  ImageF img = patchMap(32, 16);
  for (const char* name : {"e.hdr", "e.exr"}) {
    saveImage(dir / name, img);
    const ImageF back = loadLinearImage(dir / name);
    ASSERT_EQ(back.width, 32u);
    ASSERT_EQ(back.height, 16u);
    for (size_t i = 0; i < img.pixels.size(); ++i) {
      // RGBE shares one exponent: each channel is good to 1/256 of the pixel's largest.
      const glm::vec4 p = img.pixels[i];
      const float tol = std::max({p.r, p.g, p.b}) / 128.0f + 1e-6f;
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(back.pixels[i][c], p[c], tol) << name;
    }
  }
  std::ofstream(dir / "bad.hdr") << "not an image";
  EXPECT_THROW(loadLinearImage(dir / "bad.hdr"), Error);
  EXPECT_THROW(Environment::load({(dir / "e.png").string(), 1.0f, 0.0f}), UsageError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rtr
