#include "scene/cluster_lod.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numeric>
#include <span>
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
// given, so a group's work must not scale with the whole mesh), numbered in order of first use.
struct Local {
  std::vector<uint32_t> toMesh;  // local vertex -> mesh vertex
  std::vector<glm::vec3> positions;
  Indices indices;
  Local(const Indices& tris, const Mesh& mesh) : indices(tris.size()) {
    // Open addressing over a power of two at least twice the corners: one allocation, not one per vertex.
    size_t size = 64;
    while (size < 2 * tris.size()) size *= 2;
    std::vector<uint32_t> slot(size, UINT32_MAX);  // a local vertex, or none
    toMesh.reserve(tris.size()), positions.reserve(tris.size());
    for (size_t i = 0; i < tris.size(); ++i) {
      size_t h = (tris[i] * 0x9E3779B1u) & (size - 1);
      while (slot[h] != UINT32_MAX && toMesh[slot[h]] != tris[i]) h = (h + 1) & (size - 1);
      if (slot[h] == UINT32_MAX) {
        slot[h] = uint32_t(toMesh.size());
        toMesh.push_back(tris[i]), positions.push_back(mesh.positions[tris[i]]);
      }
      indices[i] = slot[h];
    }
  }
};

// Splits a group's simplified triangles (its local vertices) into clusters of at most 64 vertices and
// 124 triangles (as the mesh's own), with the mesh's vertex indices.
std::vector<Indices> split(const Indices& tris, const Local& l) {
  constexpr size_t kMaxV = CLUSTER_MAX_VERTICES, kMaxT = CLUSTER_MAX_TRIANGLES;
  std::vector<meshopt_Meshlet> ml(meshopt_buildMeshletsBound(tris.size(), kMaxV, kMaxT));
  std::vector<unsigned> verts(ml.size() * kMaxV);
  std::vector<unsigned char> local(ml.size() * kMaxT * 3);
  ml.resize(meshopt_buildMeshlets(ml.data(), verts.data(), local.data(), tris.data(), tris.size(), &l.positions[0].x,
                                  l.positions.size(), sizeof(glm::vec3), kMaxV, kMaxT, 0.0f));
  std::vector<Indices> out;
  for (const meshopt_Meshlet& m : ml) {
    Indices c(size_t(m.triangle_count) * 3);
    for (size_t k = 0; k < c.size(); ++k) c[k] = l.toMesh[verts[m.vertex_offset + local[m.triangle_offset + k]]];
    out.push_back(std::move(c));
  }
  return out;
}

// Each vertex's first vertex at the same position: clusters on the two sides of a seam (vertices split
// by normal or uv) are neighbours, so a group may hold both sides and the simplifier sees the seam. The
// positions' bits are sorted with their vertices (a comparator that looked them up missed the cache at
// every step), then each fixed piece of the sorted list names its runs from the run's first vertex.
std::vector<uint32_t> positionIds(const Mesh& mesh, unsigned threads) {
  struct Key {
    std::array<uint32_t, 3> bits;
    uint32_t vertex;
    auto operator<=>(const Key&) const = default;
  };
  constexpr size_t kPiece = size_t(1) << 16;
  const size_t n = mesh.positions.size(), pieces = (n + kPiece - 1) / kPiece;
  std::vector<Key> keys(n);
  std::vector<uint32_t> id(n);
  parallelFor(pieces, threads, [&](size_t p) {
    for (size_t v = p * kPiece; v < std::min(n, (p + 1) * kPiece); ++v) {
      std::memcpy(keys[v].bits.data(), &mesh.positions[v], sizeof(keys[v].bits));
      keys[v].vertex = uint32_t(v);
    }
  });
  parallelSort(keys, threads);
  parallelFor(pieces, threads, [&](size_t p) {
    const size_t begin = p * kPiece, end = std::min(n, begin + kPiece);
    const auto run =
        std::partition_point(keys.begin(), keys.begin() + begin, [&](const Key& k) { return k.bits < keys[begin].bits; });
    uint32_t first = run->vertex;  // keys[begin]'s own where its run starts in this piece
    for (size_t k = begin; k < end; ++k) {
      if (k > begin && keys[k].bits != keys[k - 1].bits) first = keys[k].vertex;
      id[keys[k].vertex] = first;
    }
  });
  return id;
}

// Groups of up to kGroupSize neighbouring clusters of a level, over the whole level: grown greedily in the
// clusters' order (split() makes it spatially coherent), each time by the cluster that shares the most
// edges with the group, so each group's outer border is short and locking it leaves most of the group
// free to simplify. Neighbours are found over the whole level: grouping within runs of consecutive
// clusters kept every group inside the strip of the mesh that one run of level-0 clusters covers, and
// the strips' borders stayed locked at every level (the 100M temple's statue kept 12 M triangles).
constexpr size_t kGroupSize = 4;
constexpr uint32_t kEdgePiece = 1024;           // clusters per piece of the edge listing (all cores)
constexpr size_t kListPiece = size_t(1) << 16;  // entries per piece of a whole-level list
constexpr size_t kRecordPiece = 256;            // clusters or groups per piece of a level's records

// The pieces one after another (copied on all cores); the pieces are emptied.
template <class T>
std::vector<T> joined(std::vector<std::vector<T>>& pieces, unsigned threads) {
  std::vector<size_t> at(pieces.size() + 1, 0);
  for (size_t p = 0; p < pieces.size(); ++p) at[p + 1] = at[p] + pieces[p].size();
  std::vector<T> out(at.back());
  parallelFor(pieces.size(), threads, [&](size_t p) {
    std::copy(pieces[p].begin(), pieces[p].end(), out.begin() + at[p]);
    pieces[p] = {};
  });
  return out;
}

std::vector<std::vector<uint32_t>> groupLevel(const std::vector<Indices>& clusters, const std::vector<uint32_t>& pos,
                                              unsigned threads) {
  const uint32_t n = uint32_t(clusters.size());
  // Each cluster's outer edges (used once in it), vertices by position: only these can be shared.
  struct Entry {
    uint64_t edge;
    uint32_t cluster;
    bool operator<(const Entry& o) const { return edge != o.edge ? edge < o.edge : cluster < o.cluster; }
  };
  std::vector<std::vector<Entry>> perPiece((n + kEdgePiece - 1) / kEdgePiece);
  parallelFor(perPiece.size(), threads, [&](size_t p) {
    std::vector<uint64_t> edges;
    for (uint32_t c = uint32_t(p) * kEdgePiece; c < std::min<uint64_t>(n, uint64_t(p + 1) * kEdgePiece); ++c) {
      edges.clear();
      const Indices& t = clusters[c];
      for (size_t k = 0; k < t.size(); ++k) {
        const uint32_t u = pos[t[k]], v = pos[t[k - k % 3 + (k + 1) % 3]];
        if (u != v) edges.push_back(uint64_t(std::min(u, v)) << 32 | std::max(u, v));
      }
      std::sort(edges.begin(), edges.end());
      for (size_t i = 0, j; i < edges.size(); i = j) {
        for (j = i + 1; j < edges.size() && edges[j] == edges[i];) ++j;
        if (j - i == 1) perPiece[p].push_back({edges[i], c});
      }
    }
  });
  std::vector<Entry> all = joined(perPiece, threads);
  parallelSort(all, threads);
  // The pairs of clusters that share each edge, in fixed pieces of the list, each taking the edges whose
  // entries start in it.
  std::vector<std::vector<uint64_t>> pairPieces((all.size() + kListPiece - 1) / kListPiece);
  parallelFor(pairPieces.size(), threads, [&](size_t p) {
    size_t i = p * kListPiece;
    const size_t end = std::min(all.size(), i + kListPiece);
    while (i > 0 && i < end && all[i].edge == all[i - 1].edge) ++i;
    for (size_t j; i < end; i = j) {
      for (j = i + 1; j < all.size() && all[j].edge == all[i].edge;) ++j;
      for (size_t a = i; a < j; ++a)
        for (size_t b = a + 1; b < j; ++b) pairPieces[p].push_back(uint64_t(all[a].cluster) << 32 | all[b].cluster);
    }
  });
  all = {};
  std::vector<uint64_t> pairs = joined(pairPieces, threads);  // (a << 32 | b), a < b: one per edge the two share
  parallelSort(pairs, threads);
  // Neighbours per cluster, with the edges they share (in neighbour order).
  std::vector<uint32_t> first(n + 1, 0);
  std::vector<std::pair<uint32_t, uint32_t>> links;
  for (size_t i = 0, j; i < pairs.size(); i = j) {
    for (j = i + 1; j < pairs.size() && pairs[j] == pairs[i];) ++j;
    ++first[(pairs[i] >> 32) + 1], ++first[uint32_t(pairs[i]) + 1];
  }
  for (uint32_t c = 0; c < n; ++c) first[c + 1] += first[c];
  links.resize(first[n]);
  std::vector<uint32_t> fill(first.begin(), first.end() - 1);
  for (size_t i = 0, j; i < pairs.size(); i = j) {
    for (j = i + 1; j < pairs.size() && pairs[j] == pairs[i];) ++j;
    const uint32_t a = uint32_t(pairs[i] >> 32), b = uint32_t(pairs[i]), e = uint32_t(j - i);
    links[fill[a]++] = {b, e}, links[fill[b]++] = {a, e};
  }
  parallelFor((n + kEdgePiece - 1) / kEdgePiece, threads, [&](size_t p) {
    for (uint32_t c = uint32_t(p) * kEdgePiece; c < std::min<uint64_t>(n, uint64_t(p + 1) * kEdgePiece); ++c)
      std::sort(links.begin() + first[c], links.begin() + first[c + 1]);
  });
  auto neighbours = [&](uint32_t c) { return std::span(links.data() + first[c], first[c + 1] - first[c]); };

  std::vector<int> group(n, -1);
  std::vector<std::vector<uint32_t>> groups;
  std::vector<std::pair<uint32_t, uint32_t>> shared;  // (candidate, edges shared with the group)
  for (uint32_t seed = 0; seed < n; ++seed) {
    if (group[seed] >= 0) continue;
    std::vector<uint32_t> g{seed};
    group[seed] = int(groups.size());
    while (g.size() < kGroupSize) {
      shared.clear();
      for (uint32_t m : g)
        for (const auto& link : neighbours(m)) {
          const uint32_t nb = link.first, edges = link.second;  // not a structured binding: clang 14 cannot capture one
          if (group[nb] >= 0) continue;
          auto it = std::find_if(shared.begin(), shared.end(), [&](auto& s) { return s.first == nb; });
          if (it == shared.end()) shared.push_back({nb, edges});
          else it->second += edges;
        }
      if (shared.empty()) break;
      const auto best = std::min_element(shared.begin(), shared.end(), [](auto& a, auto& b) {
        return a.second != b.second ? a.second > b.second : a.first < b.first;
      });
      group[best->first] = int(groups.size());
      g.push_back(best->first);
    }
    groups.push_back(std::move(g));
  }
  // A cluster left alone (its neighbours taken) joins the group it shares most edges with: alone it
  // could not be simplified.
  for (size_t gi = 0; gi < groups.size(); ++gi) {
    if (groups[gi].size() != 1) continue;
    const uint32_t c = groups[gi][0];
    uint32_t best = n, bestEdges = 0;
    for (auto [nb, edges] : neighbours(c))
      if (groups[group[nb]].size() > 1 && (edges > bestEdges || (edges == bestEdges && nb < best))) best = nb, bestEdges = edges;
    if (best == n) continue;
    groups[group[best]].push_back(c);
    group[c] = group[best];
    groups[gi].clear();
  }
  std::erase_if(groups, [](const std::vector<uint32_t>& g) { return g.empty(); });
  return groups;
}

// The longest edge of the triangles of `out` that are not triangles of `in` (0 if none): what a
// simplification made, as opposed to what it kept. Both over the same vertices.
float longestNewEdge(const Indices& in, const Indices& out, const std::vector<glm::vec3>& positions) {
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
      longest = std::max(longest, glm::distance(positions[out[t + e]], positions[out[t + (e + 1) % 3]]));
  }
  return longest;
}

// A stuck group's triangles over one vertex per position, the group's first vertex there (so the
// attributes are the group's own: a vertex elsewhere at that position, on another face of a crease,
// shaded an engine's fins with the wrong normals), triangles with two corners at one position left out.
Indices weldedByPosition(const Indices& tris, const std::vector<uint32_t>& pos) {
  std::unordered_map<uint32_t, uint32_t> first;  // position id -> the group's first vertex there
  auto one = [&](uint32_t v) { return first.try_emplace(pos[v], v).first->second; };
  Indices out;
  out.reserve(tris.size());
  for (size_t t = 0; t < tris.size(); t += 3) {
    const uint32_t a = one(tris[t]), b = one(tris[t + 1]), c = one(tris[t + 2]);
    if (a != b && b != c && a != c) out.insert(out.end(), {a, b, c});
  }
  return out;
}

// Simplifies a group's triangles towards half, its border locked, over the group's own vertices (the
// simplifier's cost follows the vertex count it is given). Returns the triangles (local vertices) and the
// error in object-space units.
Indices simplifyGroup(const Local& l, float& error) {
  Indices out(l.indices.size());
  const size_t target = (l.indices.size() / 6) * 3;
  float relative = 0.0f;
  out.resize(meshopt_simplify(out.data(), l.indices.data(), l.indices.size(), &l.positions[0].x, l.positions.size(),
                              sizeof(glm::vec3), target, 1.0f, meshopt_SimplifyLockBorder, &relative));
  // The simplifier's error is relative to the extent of what it was given: back to object-space units.
  error = relative * meshopt_simplifyScale(&l.positions[0].x, l.positions.size(), sizeof(glm::vec3));
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
  std::vector<LodCluster> lodClusters;  // moved into `lod` once made
  std::vector<uint32_t> lodIndices;
  if (mesh.clusters.empty()) throw Error("mesh '" + mesh.name + "': a cluster hierarchy needs the mesh's clusters");
  const float scale = meshopt_simplifyScale(&mesh.positions[0].x, mesh.positions.size(), sizeof(glm::vec3));
  const float epsilon = std::max(scale, 1e-30f) * 1e-7f;  // parents' errors rise at least by this
  const uint32_t base = mesh.triangleCount();

  // Level 0: the mesh's clusters as they are (the same triangles, ids and bounds the renderer draws).
  // Room for all levels (levels above 0 hold about as many triangles as the mesh and twice its clusters;
  // what is not used is never touched): no level copies the ones below it again.
  const size_t n0 = mesh.clusters.size();
  lodClusters.reserve(3 * n0);
  lodIndices.reserve(mesh.indices.size() * 3 / 2);
  lodClusters.resize(n0);
  std::vector<Indices> current(n0);
  std::vector<uint32_t> ids(n0);
  std::vector<uint8_t> stuckBefore(n0, 0);  // per current cluster: 1 where a group of it was stuck before
  parallelFor((n0 + kRecordPiece - 1) / kRecordPiece, threads, [&](size_t p) {
    for (size_t i = p * kRecordPiece; i < std::min(n0, (p + 1) * kRecordPiece); ++i) {
      const Cluster& mc = mesh.clusters[i];
      LodCluster& c = lodClusters[i];
      c.firstTriangle = mc.firstTriangle;
      c.triangleCount = mc.triangleCount;
      c.center = mc.center;
      c.radius = mc.radius;
      c.coneAxis = mc.coneAxis;
      c.coneCutoff = mc.coneCutoff;
      c.sphere = glm::vec4(mc.center, mc.radius);
      c.parentSphere = c.sphere;
      c.parentError = shader::LOD_ERROR_INFINITE;
      ids[i] = uint32_t(i);
      const auto* t = mesh.indices.data() + size_t(mc.firstTriangle) * 3;
      current[i].assign(t, t + size_t(mc.triangleCount) * 3);
    }
  });
  auto made = [&](size_t tris, const meshopt_Bounds& b, uint32_t level, size_t firstIndex, glm::vec4 sphere, float error) {
    LodCluster c;
    c.firstTriangle = base + uint32_t(firstIndex / 3);
    c.triangleCount = uint32_t(tris);
    c.level = level;
    c.center = {b.center[0], b.center[1], b.center[2]};
    c.radius = b.radius;
    c.coneAxis = {b.cone_axis[0], b.cone_axis[1], b.cone_axis[2]};
    c.coneCutoff = b.cone_cutoff;
    c.sphere = sphere;
    c.error = error;
    c.parentSphere = c.sphere;
    c.parentError = shader::LOD_ERROR_INFINITE;
    return c;
  };

  const std::vector<uint32_t> pos = positionIds(mesh, threads);
  lod.levels = 1;
  for (uint32_t level = 1; current.size() > 1 && level < 64; ++level) {
    const std::vector<std::vector<uint32_t>> groups = groupLevel(current, pos, threads);
    // Each group is simplified and split on its own (all cores); the results are taken in group order.
    struct Result {
      glm::vec4 sphere{0.0f};
      float error = 0.0f;
      std::vector<Indices> clusters;  // empty: stuck, its clusters are grouped again at the next level
      std::vector<meshopt_Bounds> bounds;
      LodGroupStats stats;
    };
    std::vector<Result> results(groups.size());
    parallelFor(groups.size(), threads, [&](size_t gi) {
      const std::vector<uint32_t>& g = groups[gi];
      Result& r = results[gi];
      r.stats = {level - 1, 1, uint32_t(current[g[0]].size() / 3)};
      if (g.size() < 2) return;  // alone: nothing around it to share a border with
      Indices tris;
      tris.reserve(g.size() * CLUSTER_MAX_TRIANGLES * 3);
      r.sphere = lodClusters[ids[g[0]]].sphere;
      float childError = 0.0f;
      for (uint32_t k : g) {
        tris.insert(tris.end(), current[k].begin(), current[k].end());
        r.sphere = merge(r.sphere, lodClusters[ids[k]].sphere);
        childError = std::max(childError, lodClusters[ids[k]].error);
      }
      auto stuck = [&](const Indices& s) { return s.empty() || s.size() * 6 > tris.size() * 5; };
      Local l(tris, mesh);
      Indices simpler = simplifyGroup(l, r.error);
      bool welded = false;
      // Stuck before (grouped again since) and stuck again: vertices at one position with different
      // attributes are kept apart by the simplifier (a seam), and where many meet (the poles of a dense
      // sphere, its rings coincident in float) it locks them, whatever the grouping. Then the group is
      // simplified again over one vertex per position: its own seams given up (a made triangle takes one
      // of the group's vertices' attributes there), its border with other groups locked as before. Only
      // then: a first-time stuck group mostly simplifies when grouped again, seams kept.
      const bool again = std::any_of(g.begin(), g.end(), [&](uint32_t k) { return stuckBefore[k] > 0; });
      if (stuck(simpler) && again) {
        const Indices byPosition = weldedByPosition(tris, pos);
        if (!byPosition.empty()) {
          Local lw(byPosition, mesh);
          float error = 0.0f;
          Indices s = simplifyGroup(lw, error);
          if (!stuck(s)) l = std::move(lw), simpler = std::move(s), r.error = error, welded = true;
        }
      }
      r.stats = {level - 1, uint32_t(g.size()), uint32_t(tris.size() / 3), 0, r.error, 0.0f, r.sphere.w, welded};
      if (stuck(simpler)) return;
      r.stats.trianglesOut = uint32_t(simpler.size() / 3);
      // The error also bounds the size of the triangles the simplification made: where it moves no
      // surface (a flat floor: error 0) it would otherwise make triangles that are drawn at any distance,
      // however many pixels they cover. So a triangle of the cut spans at most kLodEdgePerError × the
      // threshold in pixels (fewer where it is farther than its sphere's nearest point).
      r.stats.edgeError = longestNewEdge(l.indices, simpler, l.positions) / kLodEdgePerError;
      r.error = std::max(r.error, r.stats.edgeError);
      r.error = std::max(r.error, childError + epsilon);  // monotone up the hierarchy, strictly
      r.clusters = split(simpler, l);
      for (const Indices& c : r.clusters)
        r.bounds.push_back(clusterBounds(c.data(), c.size(), mesh.positions.data(), mesh.positions.size(), backfaceCone));
    });
    // The results in group order: where each group's go is counted first, then they are copied on all
    // cores. A stuck group's clusters are grouped again with the next level's: their neighbours there are
    // coarser and grouped differently, so the border that held them is mostly inside the new group. (As
    // roots they were in every cut.)
    struct Place {
      size_t next = 0, cluster = 0, index = 0;
    };
    std::vector<Place> at(groups.size() + 1);
    bool progress = false;
    for (size_t gi = 0; gi < groups.size(); ++gi) {
      const Result& r = results[gi];
      if (stats) stats->push_back(r.stats);
      progress |= !r.clusters.empty();
      size_t indices = 0;
      for (const Indices& c : r.clusters) indices += c.size();
      at[gi + 1] = {at[gi].next + (r.clusters.empty() ? groups[gi].size() : r.clusters.size()),
                    at[gi].cluster + r.clusters.size(), at[gi].index + indices};
    }
    if (!progress) break;
    std::vector<Indices> next(at.back().next);
    std::vector<uint32_t> nextIds(at.back().next);
    std::vector<uint8_t> nextStuck(at.back().next, 0);
    const size_t firstCluster = lodClusters.size(), firstIndex = lodIndices.size();
    lodClusters.resize(firstCluster + at.back().cluster);
    lodIndices.resize(firstIndex + at.back().index);
    parallelFor((groups.size() + kRecordPiece - 1) / kRecordPiece, threads, [&](size_t p) {
      for (size_t gi = p * kRecordPiece; gi < std::min(groups.size(), (p + 1) * kRecordPiece); ++gi) {
        Result& r = results[gi];
        size_t nx = at[gi].next, c = firstCluster + at[gi].cluster, ix = firstIndex + at[gi].index;
        for (uint32_t k : groups[gi]) {
          if (r.clusters.empty()) {
            nextStuck[nx] = 1;
            next[nx] = std::move(current[k]), nextIds[nx++] = ids[k];
            continue;
          }
          lodClusters[ids[k]].parentError = r.error;
          lodClusters[ids[k]].parentSphere = r.sphere;
          current[k] = {};
        }
        for (size_t i = 0; i < r.clusters.size(); ++i, ++c) {
          lodClusters[c] = made(r.clusters[i].size() / 3, r.bounds[i], level, ix, r.sphere, r.error);
          std::copy(r.clusters[i].begin(), r.clusters[i].end(), lodIndices.begin() + ix);
          ix += r.clusters[i].size();
          next[nx] = std::move(r.clusters[i]), nextIds[nx++] = uint32_t(c);
        }
      }
    });
    lod.levels = level + 1;
    current = std::move(next);
    ids = std::move(nextIds);
    stuckBefore = std::move(nextStuck);
  }
  lod.clusters = std::move(lodClusters);
  lod.indices = std::move(lodIndices);
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
