#include "scene/framing.hpp"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "scene/lights.hpp"

namespace rtr {

double frontArea(const Scene& scene, const glm::vec3& toViewer) {
  double area = 0.0;
  for (const Mesh& m : scene.meshes) {
    const bool twoSided = m.material < scene.materials.size() && (scene.materials[m.material].flags & kMaterialDoubleSided);
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
      const glm::vec3 a = m.positions[m.indices[i]], b = m.positions[m.indices[i + 1]], c = m.positions[m.indices[i + 2]];
      const float d = glm::dot(glm::cross(b - a, c - a), toViewer);  // counter-clockwise is the front
      area += twoSided ? std::abs(d) : std::max(d, 0.0f);
    }
  }
  return 0.5 * area;
}

CameraPose framingPose(const Scene& scene, const Lens& lens, float aspect, const glm::mat4& model) {
  const Bounds bounds = transformed(scene.bounds(), model);
  if (hasOwnLights(scene)) return frameBounds(bounds, lens, aspect);
  // The preferred view keeps its place unless another sees 1.5x its front area (a solid looks alike from
  // every side; a sheet does not).
  const glm::mat3 toScene = glm::inverse(glm::mat3(model));
  auto area = [&](float yaw, float pitch) {
    const CameraPose p{{}, yaw, pitch};
    return frontArea(scene, glm::normalize(toScene * -basis(p).forward));
  };
  float bestYaw = 35.0f, bestPitch = -25.0f;
  const double preferred = area(bestYaw, bestPitch);
  double best = preferred * 1.5;
  for (float pitch : {-25.0f, 25.0f})
    for (float yaw : {35.0f, 125.0f, -145.0f, -55.0f}) {
      const double a = area(yaw, pitch);
      if (a > best) best = a, bestYaw = yaw, bestPitch = pitch;
    }
  return orbitFrame(bounds, lens, aspect, bestYaw, bestPitch);
}

}  // namespace rtr
