#include "scene/cluster_lod.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

#include "core/error.hpp"
#include "core/parallel.hpp"
#include "scene/clusters.hpp"

#include "cluster.h"
#include "cluster_lod.h"

namespace rtr {

namespace {

using Indices = std::vector<uint32_t>;

// The smallest sphere around both (exact for two spheres).
glm::vec4 merge(glm::vec4 a, glm::vec4 b) {
  const glm::vec3 ca(a), cb(b);
  const float d = glm::length(cb - ca);
  if (d + b.w <= a.w) return a;
  if (d + a.w <= b.w) return b;
  const float r = 0.5f * (d + a.w + b.w);
  return glm::vec4(ca + (cb - ca) * ((r - a.w) / d), r * (1.0f + 1e-6f));  // a hair larger: rounding
}

// A triangle list over a vertex buffer of its own (meshoptimizer's builders cost per vertex they are
// given, so a group's work must not scale with the whole mesh).
struct Local {
  std::vector<uint32_t> toMesh;  // local vertex -> mesh vertex
  std::vector<glm::vec3> positions;
  Indices indices;
  Local(const Indices& tris, const Mesh& mesh) : indices(tris.size()) {
    std::unordered_map<uint32_t, uint32_t> toLocal;
    for (size_t i = 0; i < tris.size(); ++i) {
      const auto [it, added] = toLocal.try_emplace(tris[i], uint32_t(toMesh.size()));
      if (added) toMesh.push_back(tris[i]), positions.push_back(mesh.positions[tris[i]]);
      indices[i] = it->second;
    }
  }
};

// Splits a triangle list into clusters of at most 64 vertices and 124 triangles (as the mesh's own).
std::vector<Indices> split(const Indices& tris, const Mesh& mesh) {
  constexpr size_t kMaxV = CLUSTER_MAX_VERTICES, kMaxT = CLUSTER_MAX_TRIANGLES;
  const Local l(tris, mesh);
  std::vector<meshopt_Meshlet> ml(meshopt_buildMeshletsBound(tris.size(), kMaxV, kMaxT));
  std::vector<unsigned> verts(ml.size() * kMaxV);
  std::vector<unsigned char> local(ml.size() * kMaxT * 3);
  ml.resize(meshopt_buildMeshlets(ml.data(), verts.data(), local.data(), l.indices.data(), l.indices.size(), &l.positions[0].x,
                                  l.positions.size(), sizeof(glm::vec3), kMaxV, kMaxT, 0.0f));
  std::vector<Indices> out;
  for (const meshopt_Meshlet& m : ml) {
    Indices c(size_t(m.triangle_count) * 3);
    for (size_t k = 0; k < c.size(); ++k) c[k] = l.toMesh[verts[m.vertex_offset + local[m.triangle_offset + k]]];
    out.push_back(std::move(c));
  }
  return out;
}

// Groups of up to four of clusters [first, end) that share the most edges, grown greedily in the
// clusters' order (which split() makes spatially coherent). Neighbours by shared edges keep each group's
// outer border short, so locking it still leaves most of the group free to simplify. A level is grouped
// in fixed pieces of kGroupPiece clusters, each on its own (all cores; the same groups for any thread
// count): a cluster's neighbours in another piece are not considered.
constexpr uint32_t kGroupPiece = 256;
std::vector<std::vector<uint32_t>> groupClusters(const std::vector<Indices>& clusters, uint32_t first, uint32_t end) {
  const uint32_t n = end - first;  // local numbering: cluster first + i is i
  std::unordered_map<uint64_t, uint32_t> edgeOwner;
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> shared(n);  // (neighbour, edges), per cluster
  auto addShared = [&](uint32_t a, uint32_t b) {
    for (auto* list : {&shared[a], &shared[b]}) {
      const uint32_t other = list == &shared[a] ? b : a;
      auto it = std::find_if(list->begin(), list->end(), [&](auto& p) { return p.first == other; });
      if (it == list->end()) list->push_back({other, 1});
      else ++it->second;
    }
  };
  for (uint32_t c = 0; c < n; ++c) {
    const Indices& tris = clusters[first + c];
    for (size_t t = 0; t < tris.size(); t += 3)
      for (int e = 0; e < 3; ++e) {
        const uint32_t u = tris[t + e], v = tris[t + (e + 1) % 3];
        const uint64_t key = uint64_t(std::min(u, v)) << 32 | std::max(u, v);
        const auto [it, added] = edgeOwner.try_emplace(key, c);
        if (!added && it->second != c) addShared(it->second, c);
      }
  }
  std::vector<int> group(n, -1);
  std::vector<std::vector<uint32_t>> groups;
  for (uint32_t seed = 0; seed < n; ++seed) {
    if (group[seed] >= 0) continue;
    std::vector<uint32_t> g{seed};
    group[seed] = int(groups.size());
    while (g.size() < 4) {
      uint32_t best = n, bestEdges = 0;
      for (uint32_t m : g)
        for (auto [nb, edges] : shared[m]) {
          if (group[nb] >= 0) continue;
          uint32_t total = 0;  // edges shared with the whole group
          for (uint32_t k : g)
            for (auto [nb2, e2] : shared[k])
              if (nb2 == nb) total += e2;
          if (total > bestEdges || (total == bestEdges && nb < best)) best = nb, bestEdges = total;
          (void)edges;
        }
      if (best == n) break;
      group[best] = int(groups.size());
      g.push_back(best);
    }
    groups.push_back(std::move(g));
  }
  // A cluster left alone (its neighbours taken) joins the group it shares most edges with: alone it
  // could not be simplified and would stay a root.
  for (size_t gi = 0; gi < groups.size(); ++gi) {
    if (groups[gi].size() != 1) continue;
    const uint32_t c = groups[gi][0];
    uint32_t best = n, bestEdges = 0;
    for (auto [nb, edges] : shared[c])
      if (groups[group[nb]].size() > 1 && (edges > bestEdges || (edges == bestEdges && nb < best))) best = nb, bestEdges = edges;
    if (best == n) continue;
    groups[group[best]].push_back(c);
    group[c] = group[best];
    groups[gi].clear();
  }
  std::erase_if(groups, [](const std::vector<uint32_t>& g) { return g.empty(); });
  for (std::vector<uint32_t>& g : groups)
    for (uint32_t& c : g) c += first;
  return groups;
}

// A level's groups: its pieces grouped on all cores, then taken in piece order.
std::vector<std::vector<uint32_t>> groupLevel(const std::vector<Indices>& clusters, unsigned threads) {
  const uint32_t n = uint32_t(clusters.size()), pieces = (n + kGroupPiece - 1) / kGroupPiece;
  std::vector<std::vector<std::vector<uint32_t>>> perPiece(pieces);
  parallelFor(pieces, threads, [&](size_t p) {
    const uint32_t first = uint32_t(p) * kGroupPiece;
    perPiece[p] = groupClusters(clusters, first, std::min(n, first + kGroupPiece));
  });
  std::vector<std::vector<uint32_t>> groups;
  for (auto& piece : perPiece)
    for (auto& g : piece) groups.push_back(std::move(g));
  return groups;
}

// The longest edge of the triangles of `out` that are not triangles of `in` (0 if none): what a
// simplification made, as opposed to what it kept.
float longestNewEdge(const Indices& in, const Indices& out, const Mesh& mesh) {
  auto key = [](const uint32_t* t) {  // the same triangle, same winding, whatever vertex comes first
    const int s = t[0] < t[1] ? (t[0] < t[2] ? 0 : 2) : (t[1] < t[2] ? 1 : 2);
    return std::array<uint32_t, 3>{t[s], t[(s + 1) % 3], t[(s + 2) % 3]};
  };
  std::vector<std::array<uint32_t, 3>> kept;
  for (size_t t = 0; t < in.size(); t += 3) kept.push_back(key(&in[t]));
  std::sort(kept.begin(), kept.end());
  float longest = 0.0f;
  for (size_t t = 0; t < out.size(); t += 3) {
    if (std::binary_search(kept.begin(), kept.end(), key(&out[t]))) continue;
    for (int e = 0; e < 3; ++e)
      longest = std::max(longest, glm::distance(mesh.positions[out[t + e]], mesh.positions[out[t + (e + 1) % 3]]));
  }
  return longest;
}

// Simplifies a group's triangles towards half, its border locked, in a vertex buffer of its own (the
// simplifier's cost follows the vertex count it is given). Returns the triangles (mesh vertex indices)
// and the error in object-space units.
Indices simplifyGroup(const Indices& tris, const Mesh& mesh, float& error) {
  const Local l(tris, mesh);
  Indices out(l.indices.size());
  const size_t target = (tris.size() / 6) * 3;
  float relative = 0.0f;
  out.resize(meshopt_simplify(out.data(), l.indices.data(), l.indices.size(), &l.positions[0].x, l.positions.size(),
                              sizeof(glm::vec3), target, 1.0f, meshopt_SimplifyLockBorder, &relative));
  // The simplifier's error is relative to the extent of what it was given: back to object-space units.
  error = relative * meshopt_simplifyScale(&l.positions[0].x, l.positions.size(), sizeof(glm::vec3));
  for (uint32_t& i : out) i = l.toMesh[i];
  return out;
}

}  // namespace

size_t ClusterLod::triangles(uint32_t level) const {
  size_t n = 0;
  for (const LodCluster& c : clusters) n += c.level == level ? c.triangleCount : 0;
  return n;
}

std::span<const uint32_t> lodTriangles(const Mesh& mesh, const LodCluster& c) {
  const size_t base = mesh.indices.size() / 3, first = size_t(c.firstTriangle) * 3, n = size_t(c.triangleCount) * 3;
  if (c.firstTriangle < base) return {mesh.indices.data() + first, n};
  return {mesh.lod.indices.data() + (first - base * 3), n};
}

ClusterLod buildClusterLod(const Mesh& mesh, bool backfaceCone, unsigned threads, std::vector<LodGroupStats>* stats) {
  ClusterLod lod;
  if (mesh.indices.empty() || mesh.positions.empty()) return lod;
  if (mesh.clusters.empty()) throw Error("mesh '" + mesh.name + "': a cluster hierarchy needs the mesh's clusters");
  const float scale = meshopt_simplifyScale(&mesh.positions[0].x, mesh.positions.size(), sizeof(glm::vec3));
  const float epsilon = std::max(scale, 1e-30f) * 1e-7f;  // parents' errors rise at least by this
  const uint32_t base = mesh.triangleCount();

  // Level 0: the mesh's clusters as they are (the same triangles, ids and bounds the renderer draws).
  std::vector<Indices> current;
  std::vector<uint32_t> ids;
  for (const Cluster& mc : mesh.clusters) {
    LodCluster c;
    c.firstTriangle = mc.firstTriangle;
    c.triangleCount = mc.triangleCount;
    c.center = mc.center;
    c.radius = mc.radius;
    c.coneAxis = mc.coneAxis;
    c.coneCutoff = mc.coneCutoff;
    c.sphere = glm::vec4(mc.center, mc.radius);
    c.parentSphere = c.sphere;
    c.parentError = shader::LOD_ERROR_INFINITE;
    ids.push_back(uint32_t(lod.clusters.size()));
    lod.clusters.push_back(c);
    const auto* t = mesh.indices.data() + size_t(mc.firstTriangle) * 3;
    current.emplace_back(t, t + size_t(mc.triangleCount) * 3);
  }
  auto add = [&](const Indices& tris, const meshopt_Bounds& b, uint32_t level, glm::vec4 sphere, float error) {
    LodCluster c;
    c.firstTriangle = base + uint32_t(lod.indices.size() / 3);
    c.triangleCount = uint32_t(tris.size() / 3);
    c.level = level;
    c.center = {b.center[0], b.center[1], b.center[2]};
    c.radius = b.radius;
    c.coneAxis = {b.cone_axis[0], b.cone_axis[1], b.cone_axis[2]};
    c.coneCutoff = b.cone_cutoff;
    c.sphere = sphere;
    c.error = error;
    c.parentSphere = c.sphere;
    c.parentError = shader::LOD_ERROR_INFINITE;
    lod.indices.insert(lod.indices.end(), tris.begin(), tris.end());
    lod.clusters.push_back(c);
    return uint32_t(lod.clusters.size() - 1);
  };

  lod.levels = 1;
  for (uint32_t level = 1; current.size() > 1; ++level) {
    const std::vector<std::vector<uint32_t>> groups = groupLevel(current, threads);
    // Each group is simplified and split on its own (all cores); the results are taken in group order.
    struct Result {
      glm::vec4 sphere{0.0f};
      float error = 0.0f;
      std::vector<Indices> clusters;  // empty: the group stays as it is, its clusters roots
      std::vector<meshopt_Bounds> bounds;
      LodGroupStats stats;
    };
    std::vector<Result> results(groups.size());
    parallelFor(groups.size(), threads, [&](size_t gi) {
      const std::vector<uint32_t>& g = groups[gi];
      Result& r = results[gi];
      r.stats = {level - 1, 1, uint32_t(current[g[0]].size() / 3)};
      if (g.size() < 2) return;  // alone: nothing around it to share a border with; a root
      Indices tris;
      r.sphere = lod.clusters[ids[g[0]]].sphere;
      float childError = 0.0f;
      for (uint32_t k : g) {
        tris.insert(tris.end(), current[k].begin(), current[k].end());
        r.sphere = merge(r.sphere, lod.clusters[ids[k]].sphere);
        childError = std::max(childError, lod.clusters[ids[k]].error);
      }
      const Indices simpler = simplifyGroup(tris, mesh, r.error);
      r.stats = {level - 1, uint32_t(g.size()), uint32_t(tris.size() / 3), 0, r.error, 0.0f, r.sphere.w};
      if (simpler.empty() || simpler.size() * 6 > tris.size() * 5) return;  // stuck: these stay roots
      r.stats.trianglesOut = uint32_t(simpler.size() / 3);
      // The error also bounds the size of the triangles the simplification made: where it moves no
      // surface (a flat floor: error 0) it would otherwise make triangles that are drawn at any distance,
      // however many pixels they cover. So a triangle of the cut spans at most kLodEdgePerError × the
      // threshold in pixels (fewer where it is farther than its sphere's nearest point).
      r.stats.edgeError = longestNewEdge(tris, simpler, mesh) / kLodEdgePerError;
      r.error = std::max(r.error, r.stats.edgeError);
      r.error = std::max(r.error, childError + epsilon);  // monotone up the hierarchy, strictly
      r.clusters = split(simpler, mesh);
      for (const Indices& c : r.clusters)
        r.bounds.push_back(clusterBounds(c.data(), c.size(), mesh.positions.data(), mesh.positions.size(), backfaceCone));
    });
    std::vector<Indices> next;
    std::vector<uint32_t> nextIds;
    for (size_t gi = 0; gi < groups.size(); ++gi) {
      Result& r = results[gi];
      if (stats) stats->push_back(r.stats);
      if (r.clusters.empty()) continue;
      for (uint32_t k : groups[gi]) {
        lod.clusters[ids[k]].parentError = r.error;
        lod.clusters[ids[k]].parentSphere = r.sphere;
      }
      for (size_t i = 0; i < r.clusters.size(); ++i) {
        nextIds.push_back(add(r.clusters[i], r.bounds[i], level, r.sphere, r.error));
        next.push_back(std::move(r.clusters[i]));
      }
    }
    if (next.empty()) break;
    lod.levels = level + 1;
    current = std::move(next);
    ids = std::move(nextIds);
  }
  return lod;
}

// Meshes one after another, each on all cores (its groups).
size_t buildMissingClusterLods(Scene& scene, unsigned threads) {
  size_t n = 0;
  for (Mesh& m : scene.meshes) {
    if (m.clusters.empty() || m.lod.levels > 0) continue;
    const bool cones = m.material >= scene.materials.size() || conesCull(scene.materials[m.material]);
    m.lod = buildClusterLod(m, cones, threads);
    if (m.lod.levels < 2) m.lod = {};  // nothing simpler than the mesh: nothing to store
    else ++n;
  }
  return n;
}

}  // namespace rtr
