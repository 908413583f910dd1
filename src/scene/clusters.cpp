#include "scene/clusters.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <span>

#include "cluster.h"
#include "core/bounds.hpp"
#include "core/error.hpp"
#include "core/parallel.hpp"

namespace rtr {

namespace {

// Clusters the triangles [first, end) of `mesh` and writes their indices back in place, reordered cluster by
// cluster; returns the clusters (firstTriangle counts from the mesh's first triangle). A piece reads and
// writes only its own triangles, so the pieces of a mesh run side by side.
std::vector<Cluster> clusterPiece(Mesh& mesh, size_t first, size_t end, bool backfaceCone) {
  constexpr size_t kMaxV = CLUSTER_MAX_VERTICES, kMaxT = CLUSTER_MAX_TRIANGLES;
  const size_t count = (end - first) * 3;
  // meshoptimizer allocates and clears per-vertex arrays over the whole vertex range it is given, so each
  // piece is handed only its own vertices (else a mesh of n pieces costs n times its vertex count: the
  // clusters of a 100 M-triangle mesh took 48 times those of 10 M). The local numbering keeps the global
  // order, so the clusters are the same as over the whole range: the span the piece uses when it is
  // narrow (welded meshes number vertices as their triangles come), else its sorted distinct vertices.
  uint32_t* src = mesh.indices.writable().data() + first * 3;  // a vector already (clusterMeshes)
  const auto [lo, hi] = std::minmax_element(src, src + count);
  // Scratch reused by the pieces a thread runs: these arrays are as large as the piece, and fresh ones
  // cost a clear and page faults each time.
  thread_local std::vector<uint32_t> global, local;
  thread_local std::vector<glm::vec3> gathered;
  thread_local std::vector<meshopt_Meshlet> meshlets;
  thread_local std::vector<unsigned> vertices;
  thread_local std::vector<unsigned char> triangles;
  global.clear();
  local.resize(count);
  const float* pos = &mesh.positions[*lo].x;
  size_t nv = size_t(*hi - *lo) + 1;
  if (nv <= 8 * count) {
    for (size_t k = 0; k < count; ++k) local[k] = src[k] - *lo;
  } else {
    global.assign(src, src + count);
    std::sort(global.begin(), global.end());
    global.erase(std::unique(global.begin(), global.end()), global.end());
    for (size_t k = 0; k < count; ++k)
      local[k] = uint32_t(std::lower_bound(global.begin(), global.end(), src[k]) - global.begin());
    gathered.resize(global.size());
    for (size_t v = 0; v < global.size(); ++v) gathered[v] = mesh.positions[global[v]];
    pos = &gathered[0].x;
    nv = gathered.size();
  }
  const uint32_t base = *lo;
  const size_t bound = meshopt_buildMeshletsBound(count, kMaxV, kMaxT);
  meshlets.resize(bound);
  vertices.resize(bound * kMaxV);
  triangles.resize(bound * kMaxT * 3);
  // cone_weight 0.25 trades a little spatial compactness for tighter normal cones (meshoptimizer's advice).
  const size_t made = meshopt_buildMeshlets(meshlets.data(), vertices.data(), triangles.data(), local.data(), count, pos, nv,
                                            sizeof(glm::vec3), kMaxV, kMaxT, backfaceCone ? 0.25f : 0.0f);
  std::vector<Cluster> out;
  out.reserve(made);
  size_t at = 0;  // local holds the reordered local ids from here on (every input index was read above)
  for (size_t i = 0; i < made; ++i) {
    const meshopt_Meshlet& m = meshlets[i];
    Cluster c;
    c.firstTriangle = uint32_t(first + at / 3);
    c.triangleCount = m.triangle_count;
    const size_t n = size_t(m.triangle_count) * 3;
    if (at + n > count) break;  // reported below
    for (size_t k = 0; k < n; ++k) local[at + k] = vertices[m.vertex_offset + triangles[m.triangle_offset + k]];
    const meshopt_Bounds b = clusterBounds(&local[at], n, reinterpret_cast<const glm::vec3*>(pos), nv, backfaceCone);
    for (size_t k = at; k < at + n; ++k) src[k] = global.empty() ? local[k] + base : global[local[k]];
    at += n;
    c.center = {b.center[0], b.center[1], b.center[2]};
    c.radius = b.radius;
    c.coneAxis = {b.cone_axis[0], b.cone_axis[1], b.cone_axis[2]};
    c.coneCutoff = b.cone_cutoff;
    out.push_back(c);
  }
  // meshoptimizer keeps every triangle, degenerate ones included; a mismatch would lose geometry.
  if (at != count) throw Error("mesh '" + mesh.name + "': clustering lost triangles");
  return out;
}

// Big meshes are clustered in pieces of this many triangles (in index order), on all cores: a piece
// ends with at most one part-filled cluster, and the result does not depend on the thread count (one
// big mesh, such as a scanned statue, would otherwise keep one core busy while the others wait).
constexpr size_t kPieceTriangles = size_t(1) << 16;

// `ids`: each mesh's index in what `progress` follows (with progress only).
void clusterMeshes(std::span<Mesh* const> meshes, const std::vector<bool>& backfaceCone, unsigned threads,
                   ClusterProgress* progress = nullptr, std::span<const size_t> ids = {}) {
  // meshoptimizer asserts (aborts) on non-finite cone math, which huge coordinates produce; every reader
  // refuses them with its file and place, and nothing beyond the limit reaches it from elsewhere either.
  // Checked in pieces on all cores, each mesh's positions then its indices: the first failing piece is
  // the one a single pass would have failed in.
  struct Check {
    size_t mesh, first, end;
    bool indices;
  };
  std::vector<Check> checks;
  for (size_t i = 0; i < meshes.size(); ++i) {
    for (size_t k = 0, n = meshes[i]->positions.size(); k < n; k += kPieceTriangles * 3)
      checks.push_back({i, k, std::min(n, k + kPieceTriangles * 3), false});
    for (size_t k = 0, n = meshes[i]->indices.size(); k < n; k += kPieceTriangles * 3)
      checks.push_back({i, k, std::min(n, k + kPieceTriangles * 3), true});
  }
  parallelFor(checks.size(), threads, [&](size_t j) {
    const Check& c = checks[j];
    const Mesh& m = *meshes[c.mesh];
    for (size_t k = c.first; k < c.end; ++k)
      if (!c.indices && !coordinateOk(m.positions[k]))
        throw Error("mesh '" + m.name + "': position " + std::to_string(k) +
                    " is not finite or beyond ±1e12 (the coordinate limit, docs/files-and-cli.md)");
      else if (c.indices && m.indices[k] >= m.positions.size())  // meshoptimizer asserts this too
        throw Error("mesh '" + m.name + "': index " + std::to_string(m.indices[k]) + " out of range");
  });
  struct Job {
    size_t mesh, first, end, piece;
  };
  std::vector<Job> jobs;
  std::vector<size_t> firstJob(meshes.size() + 1);
  for (Mesh* m : meshes) m->indices.writable();  // reordered in place below: a view is copied first, once
  for (size_t i = 0; i < meshes.size(); ++i) {
    firstJob[i] = jobs.size();
    for (size_t t = 0, n = meshes[i]->indices.size() / 3; t < n; t += kPieceTriangles)
      jobs.push_back({i, t, std::min(n, t + kPieceTriangles), jobs.size() - firstJob[i]});
  }
  firstJob[meshes.size()] = jobs.size();
  std::vector<std::vector<Cluster>> pieces(jobs.size());
  auto setClusters = [&](size_t i) {  // pieces in order: every triangle once, in its mesh's place
    Mesh& m = *meshes[i];
    m.lod = {};
    m.clusters.clear();
    for (size_t j = firstJob[i]; j < firstJob[i + 1]; ++j) {
      m.clusters.insert(m.clusters.end(), pieces[j].begin(), pieces[j].end());
      std::vector<Cluster>().swap(pieces[j]);
    }
  };
  parallelFor(jobs.size(), threads, [&](size_t j) {
    const Job& job = jobs[j];
    pieces[j] = clusterPiece(*meshes[job.mesh], job.first, job.end, backfaceCone[job.mesh]);
    // A writer following the build gets each mesh's triangles as the pieces before them are done; the
    // mesh's clusters are set by the thread that completes it.
    const size_t count = firstJob[job.mesh + 1] - firstJob[job.mesh];
    if (progress && progress->pieceDone(ids[job.mesh], job.piece, count, job.end)) {
      setClusters(job.mesh);
      progress->meshDone(ids[job.mesh]);
    }
  });
  for (size_t i = 0; i < meshes.size(); ++i)
    if (!progress) {
      setClusters(i);
    } else if (firstJob[i] == firstJob[i + 1]) {  // fewer than 3 indices: no piece, nothing to wait for
      setClusters(i);
      progress->meshDone(ids[i]);
    }
}

}  // namespace

void buildClusters(Mesh& mesh, bool backfaceCone) {
  mesh.clusters.clear();
  mesh.lod = {};  // built over the old triangle order
  if (mesh.indices.empty()) return;
  Mesh* one = &mesh;
  clusterMeshes({&one, 1}, {backfaceCone}, 0);
}

meshopt_Bounds clusterBounds(const uint32_t* indices, size_t count, const glm::vec3* positions, size_t vertexCount,
                             bool backfaceCone) {
  meshopt_Bounds b = meshopt_computeClusterBounds(indices, count, &positions[0].x, vertexCount, sizeof(glm::vec3));
  const glm::vec3 center{b.center[0], b.center[1], b.center[2]};
  float far2 = b.radius * b.radius;
  for (size_t k = 0; k < count; ++k) {
    const glm::vec3 d = positions[indices[k]] - center;
    far2 = std::max(far2, glm::dot(d, d));
  }
  b.radius = std::sqrt(far2);
  const float length =
      std::sqrt(b.cone_axis[0] * b.cone_axis[0] + b.cone_axis[1] * b.cone_axis[1] + b.cone_axis[2] * b.cone_axis[2]);
  const bool cone = b.cone_cutoff >= 0.0f && b.cone_cutoff < 1.0f && std::abs(length - 1.0f) <= 1e-3f;  // false for NaN
  if (!backfaceCone || !cone) b.cone_cutoff = 1.0f;
  return b;
}

bool conesCull(const Material& material) { return !(material.flags & (kMaterialAlphaMasked | kMaterialDoubleSided)); }

namespace {
bool missesClusters(const Mesh& m) { return m.clusters.empty() && !m.indices.empty(); }
}  // namespace

size_t buildMissingClusters(Scene& scene, unsigned threads, ClusterProgress* progress) {
  std::vector<Mesh*> todo;
  std::vector<size_t> ids;
  std::vector<bool> cones;
  for (Mesh& m : scene.meshes)
    if (missesClusters(m)) {
      todo.push_back(&m);
      ids.push_back(size_t(&m - scene.meshes.data()));
      cones.push_back(m.material >= scene.materials.size() || conesCull(scene.materials[m.material]));
    }
  try {
    clusterMeshes(todo, cones, threads, progress, ids);
  } catch (...) {
    if (progress) progress->stop();
    throw;
  }
  return todo.size();
}

ClusterProgress::ClusterProgress(Scene& scene) : meshes_(scene.meshes.size()) {
  for (size_t i = 0; i < scene.meshes.size(); ++i) {
    Mesh& m = scene.meshes[i];
    State& s = meshes_[i];
    s.triangles = m.indices.size() / 3;
    s.complete = !missesClusters(m);
    s.final = s.complete ? s.triangles : 0;
    if (!s.complete) m.indices.writable();
  }
}

bool ClusterProgress::pieceDone(size_t mesh, size_t piece, size_t pieces, size_t end) {
  std::lock_guard lock(mutex_);
  State& s = meshes_[mesh];
  if (s.ends.empty()) s.ends.assign(pieces, 0);
  s.ends[piece] = end;
  const size_t was = s.final;
  for (; s.next < pieces && s.ends[s.next]; ++s.next) s.final = s.ends[s.next];
  if (s.final != was) changed_.notify_all();
  return s.next == pieces && was != s.final && s.final == s.triangles;
}

void ClusterProgress::meshDone(size_t mesh) {
  std::lock_guard lock(mutex_);
  meshes_[mesh].complete = true;
  changed_.notify_all();
}

void ClusterProgress::wait(size_t mesh, size_t triangles) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] {
    if (stopped_ || finished_ || mesh >= meshes_.size()) return stopped_ || finished_;
    const State& s = meshes_[mesh];
    return s.final >= triangles && (triangles < s.triangles || s.complete);
  });
  if (stopped_) throw Error("the clusters were not built");
}

size_t ClusterProgress::finalTriangles(size_t mesh) {
  std::lock_guard lock(mutex_);
  return meshes_[mesh].final;
}

void ClusterProgress::finish() {
  std::lock_guard lock(mutex_);
  finished_ = true;
  changed_.notify_all();
}

void ClusterProgress::stop() {
  std::lock_guard lock(mutex_);
  stopped_ = true;
  changed_.notify_all();
}

}  // namespace rtr
