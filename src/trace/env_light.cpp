// The environment's light at a surface point: the Monte Carlo estimate the GPU's split-sum approximation
// is measured against (docs/environment.md). Per sample pair, one direction drawn from the environment
// (Environment::sample, by luminance) and one from the BRDF's lobes (brdf.h's brdfSampleDirection), each
// weighted by the power heuristic (Veach 1997): w_a = p_a^2 / (p_a^2 + p_b^2). Both strategies see the
// same integrand, L_env(l) f(v, l) (n.l)_+ times the visibility along l, so the sum is unbiased.
#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "brdf.h"  // shaders/shared: the BRDF and its sampling, as the GPU has them
#include "trace/spawn.hpp"
#include "trace/tracer.hpp"

namespace rtr::trace {

glm::vec3 Tracer::environmentLight(const SurfacePoint& sp, const glm::vec3& n, const glm::vec3& v, const SurfaceInputs& in,
                                   int brdf, const Frame& f, Counters& c) const {
  const TraceSettings& s = *f.s;
  const Environment& env = *f.env;
  // One strategy's sample l (scene space) with the radiance arriving along it: f L cos / p, weighted.
  auto weighted = [&](const glm::vec3& l, const glm::vec3& radiance, float pdf, float otherPdf) -> glm::vec3 {
    if (!(pdf > 0.0f) || radiance == glm::vec3(0.0f)) return glm::vec3(0.0f);
    const glm::vec3 fl = shader::pbrDirect(brdf, n, v, l, radiance, in.baseColor, in.roughness, in.metalness);
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
