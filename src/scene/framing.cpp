#include "scene/framing.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "scene/lights.hpp"
#include "core/parallel.hpp"

namespace rtr {

std::vector<double> frontAreas(const Scene& scene, std::span<const glm::vec3> toViewer, bool windingOnly) {
  // One pass for every direction: the triangle's gathers and cross product are the cost, not the dots
  // (one pass per direction took several times as long). The pass runs on all cores (parallelFor) in
  // pieces of a fixed size whose sums are added in piece order, so the result does not depend on the
  // thread count.
  constexpr size_t kPiece = size_t(1) << 16;  // triangles
  struct Piece {
    const Mesh* mesh;
    size_t first, end;
  };
  std::vector<Piece> pieces;
  for (const Mesh& m : scene.meshes)
    for (size_t t = 0, n = m.indices.size() / 3; t < n; t += kPiece) pieces.push_back({&m, t, std::min(n, t + kPiece)});
  std::vector<double> sums(pieces.size() * toViewer.size(), 0.0);
  parallelFor(pieces.size(), 0, [&](size_t p) {
    const Mesh& m = *pieces[p].mesh;
    const bool twoSided =
        !windingOnly && m.material < scene.materials.size() && (scene.materials[m.material].flags & kMaterialDoubleSided);
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

double frontArea(const Scene& scene, const glm::vec3& toViewer) { return frontAreas(scene, {&toViewer, 1}, false)[0]; }

namespace {

// The side of a staged scene to look from (a unit axis: +z, -z, +x or -x, scene space): an open side (its
// face of the bounding box less than half covered by geometry lying in it) before a closed one, then the
// side its lights lie or shine towards, then +z, the course's own view down -z.
glm::vec3 stagedSide(const Scene& scene) {
  const Bounds b = scene.bounds();
  const glm::vec3 c = b.center(), e = glm::max(b.extent(), glm::vec3(1e-6f));
  const glm::vec3 sides[] = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}};
  if (!scene.instances.empty()) return sides[0];  // placed meshes (glTF): the course's view
  double covered[4] = {};
  for (const Mesh& m : scene.meshes)  // OBJ scenes (no instances): mesh space is scene space
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
      const glm::vec3 p[3] = {m.positions[m.indices[t]], m.positions[m.indices[t + 1]], m.positions[m.indices[t + 2]]};
      const float area = 0.5f * glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
      for (int s = 0; s < 4; ++s) {
        const int axis = s < 2 ? 2 : 0;
        const float face = sides[s][axis] > 0 ? b.max[axis] : b.min[axis], tol = 0.02f * e[axis];
        if (std::abs(p[0][axis] - face) <= tol && std::abs(p[1][axis] - face) <= tol && std::abs(p[2][axis] - face) <= tol)
          covered[s] += area;
      }
    }
  glm::vec3 towards(0.0f);  // where the lights are and where they shine
  for (const Light& l : resolveLights(scene, {}).lights) {
    if (l.kind == Light::Kind::Headlight) continue;
    towards += (l.position - c) / e;
    if (l.kind == Light::Kind::Area) towards += l.normal;
  }
  int best = 0;
  float bestScore = -1e30f;
  for (int s = 0; s < 4; ++s) {
    const int axis = s < 2 ? 2 : 0;
    const float faceArea = axis == 2 ? e.x * e.y : e.z * e.y;
    const float score =
        (covered[s] < 0.5 * faceArea ? 4.0f : 0.0f) + (glm::dot(towards, sides[s]) > 0.1f ? 2.0f : 0.0f) + (s == 0 ? 1.0f : 0.0f);
    if (score > bestScore) bestScore = score, best = s;
  }
  return sides[best];
}

}  // namespace

CameraPose stagedFrame(const Scene& scene, const Lens& lens, float aspect, const glm::vec3& side) {
  // frameBounds (which looks from +z) in a frame turned so that `side` is +z.
  const Bounds b = scene.bounds();
  if (b.empty()) return {};
  const float yaw = side.z > 0.5f ? 0.0f : side.z < -0.5f ? 180.0f : side.x > 0 ? 90.0f : -90.0f;
  const glm::vec3 e = b.extent(), c = b.center();
  const glm::vec3 turned = std::abs(side.x) > 0.5f ? glm::vec3(e.z, e.y, e.x) : e;
  Bounds local;
  local.extend(-0.5f * turned);
  local.extend(0.5f * turned);
  const CameraPose p = frameBounds(local, lens, aspect);
  return {c + side * p.position.z, yaw, 0.0f};
}

CameraPose framingPose(const Scene& scene, const Lens& lens, float aspect, const glm::mat4& model) {
  const Bounds bounds = transformed(scene.bounds(), model);
  if (hasOwnLights(scene)) {
    const glm::vec3 side = stagedSide(scene);
    if (side.z > 0.5f || model != glm::mat4(1.0f)) return frameBounds(bounds, lens, aspect);
    return stagedFrame(scene, lens, aspect, side);
  }
  // The preferred view keeps its place unless another sees 1.5x its front area (a solid looks alike from
  // every side; a sheet does not).
  const glm::mat3 toScene = glm::inverse(glm::mat3(model));
  // From above: a model seen from below its horizon looks wrong way up (--camera can ask for it). Only a
  // model no face of which is wound towards any view from above (a sheet that faces down) is seen from
  // below, as the GPU culls the back of one-sided faces (and, for now, of untextured two-sided ones).
  const float yaws[] = {35.0f, 125.0f, -145.0f, -55.0f};
  auto dir = [&](float yaw, float pitch) { return glm::normalize(toScene * -basis(CameraPose{{}, yaw, pitch}).forward); };
  std::vector<glm::vec3> above;
  for (float yaw : yaws) above.push_back(dir(yaw, -25.0f));
  const std::vector<double> wound = frontAreas(scene, above, true);
  const bool facesDown = std::all_of(wound.begin(), wound.end(), [](double a) { return a == 0.0; });
  const float pitches[] = {facesDown ? 25.0f : -25.0f};
  std::vector<glm::vec3> dirs;  // the preferred view first, then every candidate
  float bestYaw = 35.0f, bestPitch = pitches[0];
  dirs.push_back(dir(bestYaw, bestPitch));
  for (float pitch : pitches)
    for (float yaw : yaws) dirs.push_back(dir(yaw, pitch));
  const std::vector<double> areas = frontAreas(scene, dirs, true);  // faces as wound: the GPU culls some backs
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
