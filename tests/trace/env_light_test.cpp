// The tracer's environment light (env_light.cpp): its Monte Carlo converges to the exact integral of the
// same BRDF under the same environment (quadrature, within the estimator's own standard error), stays
// within the white furnace's bound, is reproducible for any thread count, and survives a sun 1e5 times
// brighter than the sky.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "../shading/brdf_quadrature.hpp"
#include "environment.h"
#include "trace/procedural.hpp"
#include "trace/tracer.hpp"

namespace rtr::trace {
namespace {

constexpr double kPi = 3.14159265358979323846;

ImageF constantMap(uint32_t w, uint32_t h, glm::vec3 c) {
  return {w, h, std::vector<glm::vec4>(size_t(w) * h, glm::vec4(c, 1.0f))};
}

std::shared_ptr<const Environment> uniformEnv(float radiance = 1.0f) {
  return std::make_shared<const Environment>(constantMap(16, 8, glm::vec3(radiance)), 1.0f, 0.0f);
}

Material pbrMaterial(glm::vec3 base, float rough, float metal) {
  Material m;
  m.baseColor = base;
  m.roughness = rough;
  m.metalness = metal;
  return m;
}

// A horizontal plane (normal +y) of one material, large against the view.
Scene ground(const Material& m) {
  Scene s;
  const uint32_t mat = addMaterial(s, m);
  addMesh(s, quad({-100.0f, 0.0f, 100.0f}, {200.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -200.0f}, mat));
  return s;
}

// Environment light only (no lamps, no ambient), pbr with the given BRDF, no mirrors.
TraceSettings envSettings(std::shared_ptr<const Environment> env, Brdf brdf, int spp, uint32_t size) {
  TraceSettings ts;
  ts.width = ts.height = size;
  ts.shading = Shading::Pbr;
  ts.brdf = brdf;
  ts.bounces = 0;
  ts.lights = LightRig{{}, glm::vec3(0.0f), ""};
  ts.environment = std::move(env);
  ts.environmentVisible = false;
  ts.spp = spp;
  ts.threads = 2;
  return ts;
}

// An orthographic camera looking at the origin from view angle thetaV off the plane's normal: every
// pixel sees the same n and v, so each is an independent estimate of one number.
void lookAtGround(TraceSettings& ts, double thetaV) {
  const float pitch = -float(90.0 - thetaV * 180.0 / kPi);
  const glm::vec3 fwd(0.0f, std::sin(glm::radians(pitch)), -std::cos(glm::radians(pitch)));
  ts.pose = CameraPose{-fwd * 10.0f, 0.0f, pitch};
  ts.lens.orthographic = true;
  ts.lens.orthoHalfHeight = 1.0f;
}

struct Mean {
  double mean, se;
};
Mean meanOf(const ImageF& img, int channel) {
  double s = 0, s2 = 0;
  for (const glm::vec4& p : img.pixels) {
    s += p[channel];
    s2 += double(p[channel]) * p[channel];
  }
  const double n = double(img.pixels.size()), m = s / n;
  return {m, std::sqrt(std::max(s2 / n - m * m, 0.0) / n)};
}

int brdfId(Brdf b) { return b == Brdf::Ggx ? BRDF_GGX : BRDF_BECKMANN; }

TEST(EnvironmentLight, UniformSkyGivesTheDirectionalAlbedo) {
  struct Case {
    Brdf brdf;
    glm::vec3 base;
    float rough, metal;
  };
  const Case cases[] = {{Brdf::Ggx, glm::vec3(1.0f), 0.5f, 1.0f},
                        {Brdf::Beckmann, glm::vec3(0.5f), 0.3f, 0.0f},
                        {Brdf::Ggx, glm::vec3(1.0f), 1.0f, 0.0f},
                        {Brdf::Beckmann, glm::vec3(0.9f), 0.0f, 1.0f},
                        {Brdf::Ggx, glm::vec3(0.8f), 0.05f, 0.0f}};
  for (const Case& c : cases)
    for (double tv : {0.5, 1.25}) {
      const Scene scene = ground(pbrMaterial(c.base, c.rough, c.metal));
      const Tracer tracer(scene);
      TraceSettings ts = envSettings(uniformEnv(), c.brdf, 8, 24);
      lookAtGround(ts, tv);
      ImageF img;
      tracer.render(ts, img);
      const Mean got = meanOf(img, 0);
      const auto ref = shader::quadrature::compensatedAlbedo(brdfId(c.brdf), tv, c.base, c.rough, c.metal);
      EXPECT_NEAR(got.mean, ref.value, 4 * got.se + ref.error + 1e-4)
          << "brdf " << int(c.brdf) << " base " << c.base.x << " rough " << c.rough << " metal " << c.metal << " view " << tv
          << " se " << got.se;
    }
}

// A map with a small bright patch (a sun ~1000x the sky) and colour that varies with direction: the
// exact answer is the sum over texels of radiance times the BRDF's cosine-weighted integral over the
// texel (the tracer takes the map as piecewise constant), by a sub-grid in each texel.
ImageF sunMap(uint32_t w, uint32_t h) {
  ImageF m = constantMap(w, h, glm::vec3(0.0f));
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) m.at(x, y) = glm::vec4(0.2f + 0.3f * float(x) / w, 0.3f, 0.5f * float(y) / h, 1.0f);
  for (uint32_t y = h / 5; y < h / 5 + 2; ++y)
    for (uint32_t x = w / 2 + 1; x < w / 2 + 3; ++x) m.at(x, y) = glm::vec4(300.0f, 280.0f, 250.0f, 1.0f);
  return m;
}

// GGX's specular carries the multiple-scattering compensation, its E by quadrature (theta_v: v's angle to n).
double exactUnderMap(const ImageF& map, int brdf, glm::vec3 v, const Material& m, int sub) {
  const glm::vec3 n(0, 1, 0);
  const double e = shader::quadrature::directionalAlbedo(brdf, std::acos(double(v.y)), glm::vec3(1.0f), m.roughness, 1.0f).value;
  const double f0 = 0.04 + (double(m.baseColor.x) - 0.04) * m.metalness, ms = brdf == BRDF_GGX ? 1 + f0 * (1 / e - 1) : 1;
  double sum = 0;
  for (uint32_t y = 0; y < map.height / 2; ++y)  // the lower half is below the plane: f = 0
    for (uint32_t x = 0; x < map.width; ++x) {
      double brdfPart = 0;
      for (int a = 0; a < sub; ++a)
        for (int b = 0; b < sub; ++b) {
          const float u = (float(x) + (b + 0.5f) / sub) / map.width, vv = (float(y) + (a + 0.5f) / sub) / map.height;
          const glm::vec3 l = shader::envUvToDir({u, vv}, 0.0f);
          const double dOmega = (2 * kPi / map.width / sub) * (kPi / map.height / sub) * std::sin(vv * kPi);
          const shader::BrdfTerms t = shader::brdfTerms(brdf, n, v, l, m.baseColor, m.roughness, m.metalness);
          brdfPart += (double(t.diffuse.x) + double(t.specular.x) * ms) * std::max(double(l.y), 0.0) * dOmega;
        }
      sum += brdfPart * map.at(x, y).x;
    }
  return sum;
}

TEST(EnvironmentLight, SunAndSkyGiveTheExactIntegral) {
  const ImageF map = sunMap(64, 32);
  const auto env = std::make_shared<const Environment>(map, 1.0f, 0.0f);
  const Material mats[] = {pbrMaterial(glm::vec3(0.9f), 0.4f, 1.0f), pbrMaterial(glm::vec3(0.6f), 0.7f, 0.0f)};
  for (const Material& m : mats)
    for (Brdf brdf : {Brdf::Ggx, Brdf::Beckmann}) {
      const Scene scene = ground(m);
      const Tracer tracer(scene);
      TraceSettings ts = envSettings(env, brdf, 8, 24);
      const double tv = 0.9;
      lookAtGround(ts, tv);
      ImageF img;
      tracer.render(ts, img);
      const Mean got = meanOf(img, 0);
      // The view vector: the camera sits towards -z, above the plane.
      const glm::vec3 v(0.0f, float(std::cos(tv)), float(std::sin(tv)));
      const double fine = exactUnderMap(map, brdfId(brdf), v, m, 12), coarse = exactUnderMap(map, brdfId(brdf), v, m, 6);
      EXPECT_NEAR(got.mean, fine, 4 * got.se + std::fabs(fine - coarse) + 1e-4)
          << "brdf " << int(brdf) << " rough " << m.roughness << " metal " << m.metalness << " se " << got.se;
    }
}

// The white furnace: a white sphere in a uniform environment of radiance 1. A metal reflects at most 1
// at every roughness and angle; with GGX all of it (the multiple-scattering compensation: single
// scattering keeps 0.31 at roughness 1 seen head-on), with Beckmann what its single scattering keeps
// (docs/environment.md's table). A dielectric's diffuse is weighted by 1 - F(v.h) per light direction
// (the brief's model and glTF's Appendix B alike), which at grazing views adds the diffuse to a nearly
// total Fresnel reflection: its albedo exceeds 1 beyond ~50° from the normal (1.2 at 75°, the same table),
// so the bound is asserted only within 45°. Allowance: the estimator's noise at 1024 sample pairs a pixel
// (below 1 % here; at GGX metal roughness >= 0.5, compensated, 2-3 % a pixel: the spread measured 0.91 ..
// 1.08, so the bound there is 1.1 and the sphere's mean within 2 % of 1, measured 0.986 .. 1.003).
TEST(EnvironmentLight, WhiteFurnaceGivesNoPixelAboveOne) {
  for (Brdf brdf : {Brdf::Ggx, Brdf::Beckmann})
    for (float metal : {0.0f, 1.0f})
      for (float rough : {0.0f, 0.25f, 0.5f, 0.75f, 1.0f}) {
        Scene scene;
        addMesh(scene,
                uvSphere({0.0f, 0.0f, 0.0f}, 1.0f, 48, 96, addMaterial(scene, pbrMaterial(glm::vec3(1.0f), rough, metal))));
        const Tracer tracer(scene);
        TraceSettings ts = envSettings(uniformEnv(), brdf, 1024, 24);
        ts.pose = CameraPose{{0.0f, 0.0f, 4.0f}, 0.0f, 0.0f};
        ImageF img;
        tracer.render(ts, img);
        float mx = 0.0f, mn = 1e30f;
        double total = 0;
        int checked = 0;
        for (uint32_t y = 0; y < ts.height; ++y)
          for (uint32_t x = 0; x < ts.width; ++x) {
            const float p = img.at(x, y).x;
            ASSERT_TRUE(std::isfinite(p) && p >= 0.0f);
            const Ray r = tracer.calculateRay(ts, x, y);
            const Hit h = tracer.closestTriangle(r);
            if (!h.hit()) continue;
            const float nv = -glm::dot(tracer.surface(r, h).normal, glm::normalize(r.direction));
            if (metal == 0.0f && nv < std::cos(float(kPi) / 4)) continue;
            ++checked;
            total += p;
            mx = std::max(mx, p);
            mn = std::min(mn, p);
          }
        EXPECT_GT(checked, 40);
        const bool compensated = brdf == Brdf::Ggx && metal == 1.0f;
        EXPECT_LE(mx, compensated && rough >= 0.5f ? 1.1f : 1.02f)
            << "brdf " << int(brdf) << " metal " << metal << " rough " << rough;
        EXPECT_GT(mn, 0.25f) << "brdf " << int(brdf) << " metal " << metal << " rough " << rough;
        if (compensated) EXPECT_NEAR(total / checked, 1.0, 0.02) << "rough " << rough;
        std::printf("furnace %s metal %.0f rough %.2f: pixels %.4f .. %.4f, mean %.4f, centre %.4f\n",
                    brdf == Brdf::Ggx ? "ggx" : "beckmann", metal, rough, mn, mx, total / checked,
                    img.at(ts.width / 2, ts.height / 2).x);
      }
}

TEST(EnvironmentLight, SameImageForAnyThreadCountAndTileSize) {
  Scene scene;
  addMesh(scene, uvSphere({0.0f, 0.0f, 0.0f}, 1.0f, 16, 32, addMaterial(scene, pbrMaterial(glm::vec3(0.7f), 0.3f, 0.5f))));
  addMesh(scene, uvSphere({1.2f, 0.6f, 0.5f}, 0.5f, 16, 32, addMaterial(scene, pbrMaterial(glm::vec3(0.9f), 0.6f, 0.0f))));
  const Tracer tracer(scene);
  const auto env = std::make_shared<const Environment>(sunMap(64, 32), 1.0f, 0.4f);
  TraceSettings ts = envSettings(env, Brdf::Ggx, 3, 40);
  ts.environmentVisible = true;
  ImageF a, b, c;
  ts.threads = 1;
  tracer.render(ts, a);
  ts.threads = 3;
  ts.tileSize = 8;
  tracer.render(ts, b);
  EXPECT_EQ(a.pixels, b.pixels);
  // And the samples do differ from pixel to pixel (a shared stream would make neighbours alike).
  ts.spp = 4;
  tracer.render(ts, c);
  EXPECT_NE(a.pixels, c.pixels);
}

TEST(EnvironmentLight, MissesSeeTheEnvironmentInWorldSpace) {
  Scene scene;
  addMesh(scene, uvSphere({0.0f, 0.0f, 0.0f}, 1.0f, 8, 16, addMaterial(scene, pbrMaterial(glm::vec3(0.7f), 0.3f, 0.0f))));
  const Tracer tracer(scene);
  const auto env = std::make_shared<const Environment>(sunMap(64, 32), 1.0f, 0.4f);
  TraceSettings ts = envSettings(env, Brdf::Ggx, 1, 8);
  ts.background = glm::vec3(0.25f);
  ts.bounces = 2;
  ts.model = glm::rotate(glm::mat4(1.0f), 0.9f, glm::vec3(0.0f, 1.0f, 0.0f));
  const Ray away{{0.0f, 5.0f, 0.0f}, glm::normalize(glm::vec3(0.3f, 0.4f, -1.0f))};
  // Camera rays: the background when the environment is hidden, else the environment along the world
  // direction (the model transform turns the scene, not the sky).
  EXPECT_EQ(tracer.traceAndShade(away, ts.bounces, ts), glm::vec3(0.25f));
  ts.environmentVisible = true;
  const glm::vec3 world = glm::normalize(glm::mat3(ts.model) * away.direction);
  EXPECT_EQ(tracer.traceAndShade(away, ts.bounces, ts), env->lookup(world));
  EXPECT_NE(env->lookup(world), env->lookup(away.direction));
  // A mirror's ray (fewer bounces left) sees the environment even where the camera's would not.
  ts.environmentVisible = false;
  EXPECT_EQ(tracer.traceAndShade(away, ts.bounces - 1, ts), env->lookup(world));
}

// The estimator's error falls as 1/sqrt(spp): against a converged render (2048 sample pairs), the mean
// absolute error at 16 and at 256 sample pairs differs by about sqrt(16) = 4. A bias (a wrong weight or
// density somewhere) would show as an error that stops falling. (The RMS error is ruled by the two pixels
// of the sun's highlight and settles later.) Prints the curve for docs/environment.md.
TEST(EnvironmentLight, ErrorFallsAsOneOverTheSquareRootOfTheSampleCount) {
  Scene scene;
  const uint32_t ground = addMaterial(scene, pbrMaterial(glm::vec3(0.5f), 0.8f, 0.0f));
  addMesh(scene, quad({-4.0f, -1.0f, 4.0f}, {8.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -8.0f}, ground));
  addMesh(scene,
          uvSphere({-1.1f, 0.0f, 0.0f}, 1.0f, 24, 48, addMaterial(scene, pbrMaterial(glm::vec3(0.9f, 0.7f, 0.5f), 0.3f, 1.0f))));
  addMesh(scene, uvSphere({1.1f, 0.0f, 0.0f}, 1.0f, 24, 48, addMaterial(scene, pbrMaterial(glm::vec3(0.8f), 0.5f, 0.0f))));
  const Tracer tracer(scene);
  const auto env = std::make_shared<const Environment>(sunMap(64, 32), 1.0f, 0.3f);
  TraceSettings ts = envSettings(env, Brdf::Ggx, 2048, 32);
  ts.pose = CameraPose{{0.0f, 1.0f, 5.0f}, 0.0f, -10.0f};
  ImageF ref;
  tracer.render(ts, ref);
  double refMean = 0;
  for (const glm::vec4& p : ref.pixels) refMean += p.x;
  refMean /= double(ref.pixels.size());
  std::vector<double> mean;
  for (int spp : {1, 4, 16, 64, 256}) {
    ts.spp = spp;
    ImageF img;
    tracer.render(ts, img);
    double se = 0, mae = 0;
    for (size_t i = 0; i < img.pixels.size(); ++i) {
      const double d = double(img.pixels[i].x) - ref.pixels[i].x;
      se += d * d;
      mae += std::fabs(d);
    }
    mean.push_back(mae / double(img.pixels.size()));
    std::printf("spp %4d: mean absolute error %.4f (%.1f %% of the mean pixel), RMS %.4f\n", spp, mean.back(),
                100.0 * mean.back() / refMean, std::sqrt(se / double(img.pixels.size())));
  }
  // Sample-pair sequences are prefixes of the reference's, so the error goes as sqrt(1/N - 1/2048).
  const double expect = std::sqrt((1.0 / 16 - 1.0 / 2048) / (1.0 / 256 - 1.0 / 2048));
  EXPECT_NEAR(mean[2] / mean[4], expect, 0.25 * expect);
  for (size_t i = 1; i < mean.size(); ++i) EXPECT_LT(mean[i], mean[i - 1]);
}

// The hard case: the generated sky with its sun turned to 1e5 times the sky's mean radiance. Every pixel
// of smooth and rough, metal and dielectric spheres stays finite and >= 0, under both BRDFs.
TEST(EnvironmentLight, SunFarBrighterThanTheSkyGivesNoNanOrInfinity) {
  SkySettings sky;
  sky.width = 128;
  sky.height = 64;
  ImageF map = makeSky(sky);
  size_t sun = 0;
  double skyMean = 0;
  for (size_t i = 0; i < map.pixels.size() / 2; ++i) {
    if (map.pixels[i].x > map.pixels[sun].x) sun = i;
    skyMean += map.pixels[i].x;
  }
  skyMean /= double(map.pixels.size() / 2);
  map.pixels[sun] = glm::vec4(glm::vec3(float(1e5 * skyMean)), 1.0f);
  const auto env = std::make_shared<const Environment>(map, 1.0f, 0.0f);
  Scene scene;
  int i = 0;
  for (float metal : {0.0f, 1.0f})
    for (float rough : {0.0f, 0.02f, 0.3f, 1.0f}) {
      const uint32_t mat = addMaterial(scene, pbrMaterial(glm::vec3(0.9f, 0.7f, 0.5f), rough, metal));
      addMesh(scene, uvSphere({float(i % 4) * 2.2f - 3.3f, float(i / 4) * 2.2f - 1.1f, 0.0f}, 1.0f, 24, 48, mat));
      ++i;
    }
  const Tracer tracer(scene);
  for (Brdf brdf : {Brdf::Ggx, Brdf::Beckmann}) {
    TraceSettings ts = envSettings(env, brdf, 4, 64);
    ts.environmentVisible = true;
    ts.pose = CameraPose{{0.0f, 0.0f, 9.0f}, 0.0f, 0.0f};
    ImageF img;
    tracer.render(ts, img);
    for (const glm::vec4& p : img.pixels)
      ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && p.x >= 0 && p.y >= 0 && p.z >= 0)
          << p.x << ' ' << p.y << ' ' << p.z;
  }
}

}  // namespace
}  // namespace rtr::trace
