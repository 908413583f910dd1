// The environment's light at a surface point: the Monte Carlo estimate the GPU's split-sum approximation
// is measured against (docs/environment.md). Per sample pair, one direction drawn from the environment
// (Environment::sample, by luminance) and one from the BRDF's lobes (brdf.h's brdfSampleDirection), each
// weighted by the power heuristic (Veach 1997): w_a = p_a^2 / (p_a^2 + p_b^2). Both strategies see the
// same integrand, L_env(l) f(v, l) (n.l)_+ times the visibility along l, so the sum is unbiased.
// GGX's specular carries the multiple-scattering compensation the GPU's split sum applies
// (env_prefilter.h's envMultiScatter), with the white metal's albedo E from the same table.
#include <algorithm>
#include <array>
#include <cmath>

#include <glm/geometric.hpp>

#include "brdf.h"  // shaders/shared: the BRDF and its sampling, as the GPU has them
#include "env_prefilter.h"
#include "trace/spawn.hpp"
#include "trace/tracer.hpp"

namespace rtr::trace {

namespace {

// GGX's white-metal albedo E = A + B at (n.v, roughness): the GPU's split-sum table (64², 256 samples a
// texel, render/environment_maps.cpp's defaults) computed once, read bilinearly between texel centres.
float ggxAlbedo(float nv, float roughness) {
  constexpr int kSize = 64;
  static const std::array<float, kSize* kSize> table = [] {
    std::array<float, kSize * kSize> t{};
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        const glm::vec3 abc = shader::envBrdfLut(BRDF_GGX, (x + 0.5f) / kSize, (y + 0.5f) / kSize, 256);
        t[size_t(y) * kSize + x] = abc.x + abc.y;
      }
    return t;
  }();
  const auto coord = [](float c, int& i) {
    const float p = std::clamp(c, 0.0f, 1.0f) * kSize - 0.5f, f = std::clamp(p, 0.0f, float(kSize - 1));
    i = std::min(int(f), kSize - 2);
    return f - float(i);
  };
  int x, y;
  const float fx = coord(nv, x), fy = coord(roughness, y);
  const auto at = [&](int dx, int dy) { return table[size_t(y + dy) * kSize + x + dx]; };
  return glm::mix(glm::mix(at(0, 0), at(1, 0), fx), glm::mix(at(0, 1), at(1, 1), fx), fy);
}

}  // namespace

glm::vec3 Tracer::environmentLight(const SurfacePoint& sp, const glm::vec3& n, const glm::vec3& v, const SurfaceInputs& in,
                                   int brdf, const Frame& f, Counters& c) const {
  const TraceSettings& s = *f.s;
  const Environment& env = *f.env;
  const glm::vec3 nn = shader::brdfSafeNormal(n);
  const glm::vec3 F0 = glm::mix(glm::vec3(0.04f), glm::clamp(in.baseColor, 0.0f, 1.0f), std::clamp(in.metalness, 0.0f, 1.0f));
  const glm::vec3 ms = shader::envMultiScatter(
      brdf, F0, brdf == BRDF_GGX ? ggxAlbedo(glm::dot(nn, v), std::clamp(in.roughness, 0.0f, 1.0f)) : 1.0f);
  // One strategy's sample l (scene space) with the radiance arriving along it: f L cos / p, weighted.
  auto weighted = [&](const glm::vec3& l, const glm::vec3& radiance, float pdf, float otherPdf) -> glm::vec3 {
    if (!(pdf > 0.0f) || radiance == glm::vec3(0.0f)) return glm::vec3(0.0f);
    const shader::BrdfTerms t = shader::brdfTerms(brdf, n, v, l, in.baseColor, in.roughness, in.metalness);
    const glm::vec3 fl = (t.diffuse + t.specular * ms) * radiance * std::max(glm::dot(nn, l), 0.0f);
    if (fl == glm::vec3(0.0f)) return glm::vec3(0.0f);
    if (s.shadows) {
      if (glm::dot(sp.geomNormal, l) <= 0.0f) return glm::vec3(0.0f);  // into the surface itself
      ++c.environment;
      if (shadowed(spawnRay(sp.position, sp.geomNormal, l), f, c)) return glm::vec3(0.0f);
    }
    const float r = otherPdf / pdf;  // the power heuristic as 1 / (1 + r^2): no overflow for huge pdfs
    return fl / (pdf * (1.0f + r * r));
  };
  glm::vec3 sum(0.0f);
  const int samples = std::max(1, s.spp);
  for (int i = 0; i < samples; ++i) {
    const EnvSample es = env.sample(c.rng.uniform2());
    const glm::vec3 le = glm::normalize(f.dirToScene * es.direction);  // a similarity keeps solid angles
    sum += weighted(le, es.radiance, es.pdf, shader::brdfPdf(brdf, n, v, le, in.baseColor, in.roughness, in.metalness));

    const glm::vec3 lb = shader::brdfSampleDirection(brdf, n, v, c.rng.uniform3(), in.baseColor, in.roughness, in.metalness);
    const float pb = shader::brdfPdf(brdf, n, v, lb, in.baseColor, in.roughness, in.metalness);
    if (pb > 0.0f) {
      const glm::vec3 world = glm::normalize(f.dirToWorld * lb);
      sum += weighted(lb, env.texel(world), pb, env.pdf(world));
    }
  }
  return sum / float(samples);
}

glm::vec3 Tracer::missed(const glm::vec3& d, bool camera, const Frame& f) const {
  const TraceSettings& s = *f.s;
  if (!s.environment || s.environment->empty() || (camera && !s.environmentVisible)) return s.background;
  return s.environment->lookup(glm::normalize(f.dirToWorld * d));
}

}  // namespace rtr::trace
