#include "trace/shade.hpp"

#include <cmath>

#include <glm/geometric.hpp>

#include "core/error.hpp"

#include "brdf.h"  // shaders/shared: the GPU renderer's BRDF, compiled here as C++
#define RTR_HAVE_BRDF 1

namespace rtr::trace {

glm::vec3 blinnPhongDirect(const Material& m, const glm::vec3& n, const glm::vec3& v, const glm::vec3& l,
                           const glm::vec3& lightColor) {
  const float nl = glm::dot(n, l);
  if (!(nl > 0.0f)) return glm::vec3(0.0f);
  const glm::vec3 h = glm::normalize(l + v);
  const float nh = std::max(glm::dot(n, h), 0.0f);
  return lightColor * (m.kd * nl + m.ks * std::pow(nh, m.ns));
}

glm::vec3 blinnPhongAmbient(const Material& m, const glm::vec3& lightColor) { return m.ka * lightColor; }

bool pbrAvailable() { return RTR_HAVE_BRDF != 0; }

glm::vec3 shadePbr(const glm::vec3& n, const glm::vec3& v, const glm::vec3& l, const glm::vec3& lightColor,
                   const glm::vec3& ambient, const glm::vec3& baseColor, float roughness, float metalness,
                   const glm::vec3& emissive) {
#if RTR_HAVE_BRDF
  return rtr::shader::shadePbr(n, v, l, lightColor, ambient, baseColor, roughness, metalness, emissive);
#else
  (void)n; (void)v; (void)l; (void)lightColor; (void)ambient; (void)baseColor; (void)roughness;
  (void)metalness; (void)emissive;
  throw Error("--shading pbr: this build has no shaders/shared/brdf.h (the shared BRDF)");
#endif
}

}  // namespace rtr::trace
