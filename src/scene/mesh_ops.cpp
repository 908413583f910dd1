#include "scene/mesh_ops.hpp"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "scene/clusters.hpp"

namespace rtr {

namespace {

template <class T>
void gather(ViewOrVector<T>& v, const std::vector<uint32_t>& from) {
  if (v.empty()) return;
  std::vector<T> out(from.size());
  for (size_t i = 0; i < from.size(); ++i) out[i] = v[from[i]];
  v = std::move(out);
}

// Any unit vector perpendicular to n.
glm::vec3 perpendicular(glm::vec3 n) {
  const glm::vec3 a = std::abs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  const glm::vec3 t = glm::cross(n, a);
  const float l = glm::length(t);
  return l > 0 ? t / l : glm::vec3(1, 0, 0);
}

}  // namespace

void flatNormals(Mesh& m) {
  const std::vector<uint32_t> corners(m.indices.begin(), m.indices.end());
  gather(m.positions, corners);
  gather(m.texcoords, corners);
  gather(m.texcoords1, corners);
  gather(m.tangents, corners);
  gather(m.colors, corners);
  std::vector<glm::vec3>& normals = m.normals.writable();
  normals.assign(m.positions.size(), glm::vec3(0, 0, 1));
  for (size_t i = 0; i < corners.size(); ++i) m.indices.writable()[i] = uint32_t(i);
  for (size_t t = 0; t + 2 < corners.size(); t += 3) {
    const glm::vec3 n = glm::cross(m.positions[t + 1] - m.positions[t], m.positions[t + 2] - m.positions[t]);
    const float l = glm::length(n);
    if (l > 0 && std::isfinite(l)) normals[t] = normals[t + 1] = normals[t + 2] = n / l;
  }
}

void generateTangents(Mesh& m, const ViewOrVector<glm::vec2>& uv) {
  const size_t n = m.positions.size();
  // Angle-weighted tangent sums per vertex, one per handedness (0: +1, 1: -1), and which ones were used.
  std::vector<glm::vec3> sum[2] = {std::vector<glm::vec3>(n, glm::vec3(0)), std::vector<glm::vec3>(n, glm::vec3(0))};
  std::vector<uint8_t> used(n, 0);
  std::vector<uint8_t> cornerSide(m.indices.size(), 0);
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const uint32_t v[3] = {m.indices[t], m.indices[t + 1], m.indices[t + 2]};
    const glm::vec3 e1 = m.positions[v[1]] - m.positions[v[0]], e2 = m.positions[v[2]] - m.positions[v[0]];
    const glm::vec2 d1 = uv[v[1]] - uv[v[0]], d2 = uv[v[2]] - uv[v[0]];
    const float det = d1.x * d2.y - d2.x * d1.y;
    if (!(std::abs(det) > 0) || !std::isfinite(det)) continue;  // no uv area: no tangent from this face
    const glm::vec3 faceT = (e1 * d2.y - e2 * d1.y) / det;      // dP/du
    const glm::vec3 faceB = (e2 * d1.x - e1 * d2.x) / det;      // dP/dv
    for (int c = 0; c < 3; ++c) {
      const uint32_t vi = v[c];
      const glm::vec3 nrm = m.normals[vi];
      glm::vec3 tan = faceT - nrm * glm::dot(nrm, faceT);
      const float l = glm::length(tan);
      if (!(l > 0) || !std::isfinite(l)) continue;
      tan /= l;
      const glm::vec3 a = m.positions[v[(c + 1) % 3]] - m.positions[vi], b = m.positions[v[(c + 2) % 3]] - m.positions[vi];
      const float la = glm::length(a), lb = glm::length(b);
      if (!(la > 0 && lb > 0)) continue;
      const float angle = std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0f, 1.0f));
      const int side = glm::dot(glm::cross(nrm, tan), faceB) < 0 ? 1 : 0;
      sum[side][vi] += tan * angle;
      used[vi] |= uint8_t(1u << side);
      cornerSide[t + c] = uint8_t(side);
    }
  }
  // A vertex both sides use is split: the -1 side gets a copy.
  std::vector<uint32_t> copyOf(n, 0xFFFFFFFFu);
  std::vector<uint32_t> extra;  // source vertex of each appended one
  for (size_t v = 0; v < n; ++v)
    if (used[v] == 3) {
      copyOf[v] = uint32_t(n + extra.size());
      extra.push_back(uint32_t(v));
    }
  if (!extra.empty()) {
    auto append = [&](auto& vec) {
      if (vec.empty()) return;
      for (uint32_t s : extra) vec.push_back(vec[s]);
    };
    append(m.positions);
    append(m.normals);
    append(m.texcoords);
    append(m.texcoords1);
    append(m.colors);
    std::vector<uint32_t>& indices = m.indices.writable();
    for (size_t i = 0; i < indices.size(); ++i)
      if (cornerSide[i] == 1 && copyOf[indices[i]] != 0xFFFFFFFFu) indices[i] = copyOf[indices[i]];
  }
  std::vector<glm::vec4>& tangents = m.tangents.writable();
  tangents.assign(m.positions.size(), glm::vec4(0));
  auto finish = [&](uint32_t dst, glm::vec3 s, float w) {
    const glm::vec3 nrm = m.normals[dst];
    s -= nrm * glm::dot(nrm, s);
    const float l = glm::length(s);
    tangents[dst] = glm::vec4(l > 0 && std::isfinite(l) ? s / l : perpendicular(nrm), w);
  };
  for (size_t v = 0; v < n; ++v) {
    if (used[v] == 3) {
      finish(uint32_t(v), sum[0][v], 1.0f);
      finish(copyOf[v], sum[1][v], -1.0f);
    } else {
      const int side = used[v] == 2 ? 1 : 0;
      finish(uint32_t(v), sum[side][v], side ? -1.0f : 1.0f);
    }
  }
}

Scene flattenInstances(const Scene& in) {
  if (in.instances.empty()) return in;
  Scene out;
  out.baseDir = in.baseDir;
  out.textures = in.textures;
  out.materials = in.materials;
  out.defaultView = in.defaultView;
  out.defaultFovYDeg = in.defaultFovYDeg;
  out.lights = in.lights;
  for (const Instance& inst : in.instances) {
    Mesh m = in.meshes.at(inst.mesh);
    const glm::mat4& x = inst.transform;
    const glm::mat3 linear(x), normalMatrix = glm::transpose(glm::inverse(linear));
    const float det = glm::determinant(linear);
    m.bounds = {};
    for (glm::vec3& p : m.positions.writable()) {
      p = glm::vec3(x * glm::vec4(p, 1.0f));
      m.bounds.extend(p);
    }
    for (glm::vec3& nrm : m.normals.writable()) {
      const glm::vec3 v = normalMatrix * nrm;
      const float l = glm::length(v);
      nrm = l > 0 ? v / l : nrm;
    }
    for (glm::vec4& t : m.tangents.writable()) {
      const glm::vec3 v = linear * glm::vec3(t);
      const float l = glm::length(v);
      t = glm::vec4(l > 0 ? v / l : glm::vec3(t), det < 0 ? -t.w : t.w);
    }
    if (det < 0)  // a mirror turns the winding: swap two corners so front faces stay front faces
      for (size_t i = 0; i + 2 < m.indices.size(); i += 3) std::swap(m.indices.writable()[i + 1], m.indices.writable()[i + 2]);
    m.clusters.clear();
    out.meshes.push_back(std::move(m));
  }
  buildMissingClusters(out);
  return out;
}

}  // namespace rtr
