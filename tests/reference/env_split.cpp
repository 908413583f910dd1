// The split sum evaluated exactly on the CPU: the image the GPU's approximation would give if nothing of
// its implementation (the cube's resolution, sampled levels, half floats, the table's texels, level
// interpolation, the SH taken from a small cube level) added error. Against the tracer's converged image it
// is the approximation's own error; against the GPU's, the implementation's (docs/environment.md).
#include <cmath>

#include <glm/geometric.hpp>

#include "core/error.hpp"
#include "core/parallel.hpp"
#include "env_prefilter.h"  // shaders/shared: the split sum and its table, as the GPU has them
#include "environment.h"
#include "reference_common.hpp"
#include "trace/tracer.hpp"

namespace rtr::reftest {

ImageF splitSumCase(const ReferenceScene& rs, const PoseEntry& pe, const PairOptions& o, float maxRoughness) {
  if (!rs.environment || !rs.lights.lights.empty())
    throw Error("the exact split sum: only for cases lit by the environment alone (env_*)");
  const trace::TraceSettings ts = traceSettings(rs, pe, View::Shaded, o);
  if (ts.model != glm::mat4(1.0f)) throw Error("the exact split sum: the environment is in scene space only");
  const trace::Tracer tracer(rs.scene, o.threads);
  const Environment& env = *rs.environment;
  const ImageF& map = env.map();
  // Every texel of the map as a direction with its exact solid angle: the piecewise-constant function the
  // tracer's Monte Carlo converges to, so the sum below is the prefiltered radiance without sampling.
  struct Texel {
    glm::vec3 dir, radianceOmega;
    float omega;
  };
  std::vector<Texel> texels;
  texels.reserve(size_t(map.width) * map.height);
  const double kPi = 3.14159265358979323846;
  for (uint32_t y = 0; y < map.height; ++y) {
    const double omega = 2.0 * kPi / map.width * (std::cos(kPi * y / map.height) - std::cos(kPi * (y + 1.0) / map.height));
    for (uint32_t x = 0; x < map.width; ++x) {
      const glm::vec2 uv{(x + 0.5f) / float(map.width), (y + 0.5f) / float(map.height)};
      texels.push_back({shader::envUvToDir(uv, env.rotation()), glm::vec3(map.at(x, y)) * float(omega), float(omega)});
    }
  }
  ImageF img{o.width, o.height, std::vector<glm::vec4>(size_t(o.width) * o.height, glm::vec4(kUncovered))};
  parallelFor(o.height, o.threads, [&](size_t y) {
    for (uint32_t x = 0; x < o.width; ++x) {
      const trace::Ray ray = tracer.calculateRay(ts, x, uint32_t(y));
      const trace::Hit hit = tracer.closestTriangle(ray);
      if (!hit.hit()) continue;
      const trace::SurfacePoint sp = tracer.surface(ray, hit);
      const Material& m = *sp.material;
      if (m.roughness > maxRoughness) continue;
      if (m.texture(TextureSlot::BaseColor) != kNoTexture) throw Error("the exact split sum: untextured cases only");
      const int brdf = (m.flags & kMaterialGltf) ? BRDF_GGX : BRDF_BECKMANN;
      const glm::vec3 n = sp.normal, v = -glm::normalize(ray.direction);
      const glm::vec3 r = glm::reflect(-v, n);
      // The prefilter's lobe (env_specular_sum.comp): GGX D with n = v = r, weighted by n.l and solid angle.
      const float alpha = std::max(m.roughness * m.roughness, shader::BRDF_ALPHA_MIN), a2 = alpha * alpha;
      glm::vec3 prefiltered = env.lookup(r);  // a mirror: the radiance along r
      if (alpha > 0.01f) {
        glm::dvec3 sum(0.0);
        double weight = 0.0;
        for (const Texel& t : texels) {
          const float rl = glm::dot(r, t.dir);
          if (rl <= 0.0f) continue;
          const float k = (1.0f + rl) * 0.5f * (a2 - 1.0f) + 1.0f;
          const float w = a2 / (k * k) * rl;
          sum += glm::dvec3(t.radianceOmega * w);
          weight += double(w) * t.omega;
        }
        prefiltered = weight > 0.0 ? glm::vec3(sum / weight) : glm::vec3(0.0f);
      }
      const float nv = std::max(glm::dot(n, v), 1e-4f);
      const glm::vec3 abc = shader::envBrdfLut(brdf, nv, m.roughness, 4096);
      const glm::vec3 base = m.baseColor * glm::vec3(sp.color);
      const glm::vec3 c = shader::envSplitSum(brdf, env.irradianceSh(n), prefiltered, abc, base, m.metalness) +
                          rs.lights.ambient * glm::clamp(base, 0.0f, 1.0f);
      img.at(x, uint32_t(y)) = glm::vec4(c, 1.0f);
    }
  });
  return img;
}

}  // namespace rtr::reftest
