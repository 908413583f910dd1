#include "baseline.hpp"

#include <cstring>
#include <map>
#include <stdexcept>
#include <unordered_map>

#include <glm/geometric.hpp>
#include <tiny_obj_loader.h>

namespace bench {
namespace {

struct Key {
  float v[8];
  bool operator==(const Key& o) const { return std::memcmp(v, o.v, sizeof v) == 0; }
};
struct KeyHash {
  size_t operator()(const Key& k) const {
    size_t h = 1469598103934665603ull;
    for (float f : k.v) {
      uint32_t u;
      std::memcpy(&u, &f, 4);
      h = (h ^ u) * 1099511628211ull;
    }
    return h;
  }
};

}  // namespace

rtr::Scene baselineLoad(const std::filesystem::path& obj) {
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, obj.c_str(), obj.parent_path().c_str(), true))
    throw std::runtime_error("tinyobjloader: " + err);
  rtr::Scene scene;
  for (const auto& m : materials) {
    rtr::Material mat;
    mat.name = m.name;
    mat.baseColor = mat.kd = {m.diffuse[0], m.diffuse[1], m.diffuse[2]};
    scene.materials.push_back(mat);
  }
  const auto& P = attrib.vertices;
  for (const auto& shape : shapes) {
    // Split the shape by material, in order of first use.
    std::map<int, std::vector<size_t>> facesOf;
    std::vector<int> order;
    for (size_t f = 0; f < shape.mesh.material_ids.size(); ++f) {
      int m = shape.mesh.material_ids[f];
      if (!facesOf.count(m)) order.push_back(m);
      facesOf[m].push_back(f);
    }
    for (int mid : order) {
      rtr::Mesh mesh;
      mesh.name = shape.name;
      mesh.material = uint32_t(std::max(mid, 0));
      // Area-weighted normals per position index for corners without one.
      std::unordered_map<int, glm::vec3> gen;
      auto pos = [&](int i) { return glm::vec3(P[3 * i], P[3 * i + 1], P[3 * i + 2]); };
      for (size_t f : facesOf[mid]) {
        const auto* idx = &shape.mesh.indices[f * 3];
        glm::vec3 x =
            glm::cross(pos(idx[1].vertex_index) - pos(idx[0].vertex_index), pos(idx[2].vertex_index) - pos(idx[0].vertex_index));
        if (glm::dot(x, x) == 0.0f) continue;
        for (int k = 0; k < 3; ++k)
          if (idx[k].normal_index < 0) gen[idx[k].vertex_index] += x;
      }
      std::unordered_map<Key, uint32_t, KeyHash> ids;
      bool hasTex = false;
      for (size_t f : facesOf[mid]) {
        const auto* idx = &shape.mesh.indices[f * 3];
        glm::vec3 x =
            glm::cross(pos(idx[1].vertex_index) - pos(idx[0].vertex_index), pos(idx[2].vertex_index) - pos(idx[0].vertex_index));
        if (glm::dot(x, x) == 0.0f) continue;
        for (int k = 0; k < 3; ++k) {
          Key key{};
          glm::vec3 p = pos(idx[k].vertex_index), n;
          if (idx[k].normal_index >= 0) {
            const float* q = &attrib.normals[3 * idx[k].normal_index];
            n = {q[0], q[1], q[2]};
          } else {
            n = glm::normalize(gen[idx[k].vertex_index]);
          }
          glm::vec2 t(0.0f);
          if (idx[k].texcoord_index >= 0) {
            t = {attrib.texcoords[2 * idx[k].texcoord_index], attrib.texcoords[2 * idx[k].texcoord_index + 1]};
            hasTex = true;
          }
          float vals[8] = {p.x, p.y, p.z, n.x, n.y, n.z, t.x, t.y};
          std::memcpy(key.v, vals, sizeof vals);
          auto [it, added] = ids.try_emplace(key, uint32_t(mesh.positions.size()));
          if (added) {
            mesh.positions.push_back(p);
            mesh.normals.push_back(n);
            mesh.texcoords.push_back(t);
            mesh.bounds.extend(p);
          }
          mesh.indices.push_back(it->second);
        }
      }
      if (!hasTex) mesh.texcoords.clear();
      scene.meshes.push_back(std::move(mesh));
    }
  }
  return scene;
}

}  // namespace bench
