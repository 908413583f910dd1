#include "scene/framing.hpp"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "scene/lights.hpp"
#include "core/parallel.hpp"

namespace rtr {

std::vector<double> frontAreas(const Scene& scene, std::span<const glm::vec3> toViewer) {
  // One pass for every direction: the triangle's gathers and cross product are the cost, not the dots
  // (one pass per direction took several times as long). The pass runs on all cores (parallelFor) in
  // pieces of a fixed size whose sums are added in piece order, so the result does not depend on the
  // thread count.
  constexpr size_t kPiece = size_t(1) << 16;  // triangles
  struct Piece { const Mesh* mesh; size_t first, end; };
  std::vector<Piece> pieces;
  for (const Mesh& m : scene.meshes)
    for (size_t t = 0, n = m.indices.size() / 3; t < n; t += kPiece) pieces.push_back({&m, t, std::min(n, t + kPiece)});
  std::vector<double> sums(pieces.size() * toViewer.size(), 0.0);
  parallelFor(pieces.size(), 0, [&](size_t p) {
    const Mesh& m = *pieces[p].mesh;
    const bool twoSided = m.material < scene.materials.size() && (scene.materials[m.material].flags & kMaterialDoubleSided);
    double* area = &sums[p * toViewer.size()];
    for (size_t t = pieces[p].first; t < pieces[p].end; ++t) {
      const glm::vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
                      c = m.positions[m.indices[3 * t + 2]];
      const glm::vec3 n = glm::cross(b - a, c - a);
      for (size_t k = 0; k < toViewer.size(); ++k) {
        const float d = glm::dot(n, toViewer[k]);  // counter-clockwise is the front
        area[k] += twoSided ? std::abs(d) : std::max(d, 0.0f);
      }
    }
  });
  std::vector<double> area(toViewer.size(), 0.0);
  for (size_t p = 0; p < pieces.size(); ++p)
    for (size_t k = 0; k < toViewer.size(); ++k) area[k] += sums[p * toViewer.size() + k];
  for (double& x : area) x *= 0.5;
  return area;
}

double frontArea(const Scene& scene, const glm::vec3& toViewer) { return frontAreas(scene, {&toViewer, 1})[0]; }

CameraPose framingPose(const Scene& scene, const Lens& lens, float aspect, const glm::mat4& model) {
  const Bounds bounds = transformed(scene.bounds(), model);
  if (hasOwnLights(scene)) return frameBounds(bounds, lens, aspect);
  // The preferred view keeps its place unless another sees 1.5x its front area (a solid looks alike from
  // every side; a sheet does not).
  const glm::mat3 toScene = glm::inverse(glm::mat3(model));
  const float pitches[] = {-25.0f, 25.0f}, yaws[] = {35.0f, 125.0f, -145.0f, -55.0f};
  std::vector<glm::vec3> dirs;  // the preferred view first, then every candidate
  auto dir = [&](float yaw, float pitch) { return glm::normalize(toScene * -basis(CameraPose{{}, yaw, pitch}).forward); };
  float bestYaw = 35.0f, bestPitch = -25.0f;
  dirs.push_back(dir(bestYaw, bestPitch));
  for (float pitch : pitches)
    for (float yaw : yaws) dirs.push_back(dir(yaw, pitch));
  const std::vector<double> areas = frontAreas(scene, dirs);
  double best = areas[0] * 1.5;
  size_t k = 1;
  for (float pitch : pitches)
    for (float yaw : yaws) {
      const double a = areas[k++];
      if (a > best) best = a, bestYaw = yaw, bestPitch = pitch;
    }
  return orbitFrame(bounds, lens, aspect, bestYaw, bestPitch);
}

}  // namespace rtr
