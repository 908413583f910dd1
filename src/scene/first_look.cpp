#include "scene/first_look.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/trigonometric.hpp>

#include "core/error.hpp"
#include "scene/lights.hpp"

namespace rtr {

glm::mat3 upRotation(std::string_view a) {
  // Columns are the images of x, y, z; each a proper rotation (determinant +1).
  if (a == "+Y" || a == "+y" || a == "Y" || a == "y") return glm::mat3(1.0f);
  if (a == "-Y" || a == "-y") return glm::mat3({1, 0, 0}, {0, -1, 0}, {0, 0, -1});
  if (a == "+Z" || a == "+z" || a == "Z" || a == "z") return glm::mat3({1, 0, 0}, {0, 0, -1}, {0, 1, 0});
  if (a == "-Z" || a == "-z") return glm::mat3({1, 0, 0}, {0, 0, 1}, {0, -1, 0});
  if (a == "+X" || a == "+x" || a == "X" || a == "x") return glm::mat3({0, 1, 0}, {-1, 0, 0}, {0, 0, 1});
  if (a == "-X" || a == "-x") return glm::mat3({0, -1, 0}, {1, 0, 0}, {0, 0, 1});
  throw UsageError("--up '" + std::string(a) + "': expected +X, +Y, +Z, -X, -Y or -Z");
}

void turnScene(Scene& scene, const glm::mat3& r) {
  if (r == glm::mat3(1.0f)) return;
  if (!scene.instances.empty()) {
    for (Instance& i : scene.instances) i.transform = glm::mat4(r) * i.transform;
  } else {
    for (Mesh& m : scene.meshes) {
      m.bounds = Bounds{};
      // Each array a view of a loaded file is copied here (once): the turned scene is a new one.
      for (glm::vec3& p : m.positions.writable()) p = r * p, m.bounds.extend(p);
      for (glm::vec3& n : m.normals.writable()) n = r * n;
      for (glm::vec4& t : m.tangents.writable()) t = glm::vec4(r * glm::vec3(t), t.w);
      for (Cluster& c : m.clusters.writable()) c.center = r * c.center, c.coneAxis = r * c.coneAxis;
      // The hierarchy's bounds, cones and error spheres are object space too (the LOD cut and culling read them).
      auto turned = [&r](glm::vec4 s) { return glm::vec4(r * glm::vec3(s), s.w); };
      for (LodCluster& c : m.lod.clusters.writable()) {
        c.center = r * c.center, c.coneAxis = r * c.coneAxis;
        c.sphere = turned(c.sphere), c.parentSphere = turned(c.parentSphere);
      }
    }
  }
  for (Light& l : scene.lights) {
    l.position = r * l.position, l.corner = r * l.corner, l.edge1 = r * l.edge1, l.edge2 = r * l.edge2;
    l.normal = r * l.normal, l.direction = r * l.direction;
  }
  scene.defaultView.reset();
}

bool isCourseScene(const Scene& scene) {
  if (scene.lights.empty() && !lightsFromGeometry(scene).empty()) return true;
  return std::any_of(scene.materials.begin(), scene.materials.end(),
                     [](const Material& m) { return m.mirror > 0.0f || m.ior != 1.0f; });
}

bool drawBothSides(Scene& scene) {
  if (isCourseScene(scene)) return false;
  for (const Material& m : scene.materials)
    if (m.flags & (kMaterialDoubleSided | kMaterialGltf)) return false;
  for (Material& m : scene.materials) m.flags |= kMaterialDoubleSided;
  return !scene.materials.empty();
}

namespace {

// Whether the box is wholly outside the view volume: all its corners beyond one of its planes.
bool outsideView(const Bounds& b, const CameraPose& pose, const Lens& lens, float aspect) {
  const CameraBasis cb = basis(pose);
  const float tanY = std::tan(glm::radians(lens.fovYDeg) * 0.5f), tanX = tanY * aspect;
  int out[5] = {};
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 p =
        glm::vec3(i & 1 ? b.max.x : b.min.x, i & 2 ? b.max.y : b.min.y, i & 4 ? b.max.z : b.min.z) - pose.position;
    const float z = glm::dot(p, cb.forward), x = glm::dot(p, cb.right), y = glm::dot(p, cb.up);
    const float hx = lens.orthographic ? lens.orthoHalfHeight * aspect : z * tanX;
    const float hy = lens.orthographic ? lens.orthoHalfHeight : z * tanY;
    out[0] += !lens.orthographic && z <= 0.0f;
    out[1] += x > hx, out[2] += x<-hx, out[3] += y> hy, out[4] += y < -hy;
  }
  return std::any_of(std::begin(out), std::end(out), [](int n) { return n == 8; });
}

}  // namespace

std::string emptyImageWarning(const Scene& scene, const CameraPose& pose, const Lens& lens, float aspect, bool anyLitPixel,
                              size_t lightCount) {
  const Bounds b = scene.bounds();
  if (b.empty() || outsideView(b, pose, lens, aspect))
    return "the scene lies wholly outside the view: the image is empty (drop --camera, or press F in the window)";
  if (anyLitPixel) return {};
  if (lightCount == 0) return "the image has no lit pixel: the scene has no lights and --no-default-light is set";
  return "the image has no lit pixel: the lights reach no surface the camera sees (try --light x,y,z, --ambient, "
         "or another --camera)";
}

}  // namespace rtr
