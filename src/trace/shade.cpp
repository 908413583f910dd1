#include "trace/shade.hpp"

#include <cmath>

#include <glm/geometric.hpp>

#include "brdf.h"  // shaders/shared: the GPU renderer's BRDF, compiled here as C++

namespace rtr::trace {

glm::vec3 blinnPhongDirect(const Material& m, const glm::vec3& kd, const glm::vec3& n, const glm::vec3& v, const glm::vec3& l,
                           const glm::vec3& lightColor) {
  const float nl = glm::dot(n, l);
  if (!(nl > 0.0f)) return glm::vec3(0.0f);
  const glm::vec3 h = glm::normalize(l + v);
  const float nh = std::max(glm::dot(n, h), 0.0f);
  return lightColor * (kd * nl + m.ks * std::pow(nh, m.ns));
}

glm::vec3 blinnPhongAmbient(const Material& m, const glm::vec3& lightColor) { return m.ka * lightColor; }

glm::vec3 pbrDirect(int brdf, const glm::vec3& n, const glm::vec3& v, const glm::vec3& l, const glm::vec3& lightColor,
                    const glm::vec3& baseColor, float roughness, float metalness) {
  return shader::pbrDirect(brdf, n, v, l, lightColor, baseColor, roughness, metalness);
}

}  // namespace rtr::trace
