#include "trace/procedural.hpp"

#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

namespace rtr::trace {

Mesh uvSphere(glm::vec3 c, float radius, uint32_t rings, uint32_t segments, uint32_t material) {
  Mesh m;
  m.name = "sphere";
  m.material = material;
  rings = std::max(rings, 2u);
  segments = std::max(segments, 3u);
  const double pi = std::numbers::pi;
  auto push = [&](glm::dvec3 dir) {
    m.positions.push_back(c + glm::vec3(dir) * radius);
    m.normals.push_back(glm::vec3(dir));
  };
  push({0, 1, 0});  // north pole: index 0
  for (uint32_t r = 1; r < rings; ++r) {
    const double theta = pi * double(r) / double(rings);
    for (uint32_t s = 0; s < segments; ++s) {
      const double phi = 2.0 * pi * double(s) / double(segments);
      push({std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)});
    }
  }
  push({0, -1, 0});  // south pole
  const uint32_t south = uint32_t(m.positions.size() - 1);
  auto ring = [&](uint32_t r, uint32_t s) { return 1 + (r - 1) * segments + s % segments; };
  for (uint32_t s = 0; s < segments; ++s) {
    m.indices.insert(m.indices.end(), {0u, ring(1, s), ring(1, s + 1)});
    for (uint32_t r = 1; r + 1 < rings; ++r) {
      const uint32_t a = ring(r, s), b = ring(r, s + 1), cc = ring(r + 1, s), d = ring(r + 1, s + 1);
      m.indices.insert(m.indices.end(), {a, cc, d, a, d, b});
    }
    m.indices.insert(m.indices.end(), {ring(rings - 1, s), south, ring(rings - 1, s + 1)});
  }
  for (const glm::vec3& p : m.positions) m.bounds.extend(p);
  return m;
}

Mesh quad(glm::vec3 corner, glm::vec3 e1, glm::vec3 e2, uint32_t material) {
  Mesh m;
  m.name = "quad";
  m.material = material;
  m.positions = {corner, corner + e1, corner + e1 + e2, corner + e2};
  const glm::vec3 n = glm::normalize(glm::cross(e1, e2));
  m.normals.assign(4, n);
  m.texcoords = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  m.indices = {0, 1, 2, 0, 2, 3};
  for (const glm::vec3& p : m.positions) m.bounds.extend(p);
  return m;
}

Mesh box(glm::vec3 lo, glm::vec3 hi, uint32_t material, bool inward) {
  Mesh m;
  m.name = "box";
  m.material = material;
  // Each face its own four vertices, so that normals are flat.
  const glm::vec3 d = hi - lo;
  auto face = [&](glm::vec3 corner, glm::vec3 e1, glm::vec3 e2) {
    if (inward) std::swap(e1, e2);
    Mesh q = quad(corner, e1, e2, material);
    const uint32_t base = uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), q.positions.begin(), q.positions.end());
    m.normals.insert(m.normals.end(), q.normals.begin(), q.normals.end());
    for (uint32_t i : q.indices) m.indices.push_back(base + i);
  };
  const glm::vec3 X{d.x, 0, 0}, Y{0, d.y, 0}, Z{0, 0, d.z};
  face(lo, Y, X);      // -z
  face(lo + Z, X, Y);  // +z
  face(lo, Z, Y);      // -x
  face(lo + X, Y, Z);  // +x
  face(lo, X, Z);      // -y
  face(lo + Y, Z, X);  // +y
  for (const glm::vec3& p : m.positions) m.bounds.extend(p);
  return m;
}

uint32_t addMaterial(Scene& scene, Material m) {
  scene.materials.push_back(std::move(m));
  return uint32_t(scene.materials.size() - 1);
}

void addMesh(Scene& scene, Mesh mesh) {
  mesh.bounds = {};
  for (const glm::vec3& p : mesh.positions) mesh.bounds.extend(p);
  scene.meshes.push_back(std::move(mesh));
}

}  // namespace rtr::trace
