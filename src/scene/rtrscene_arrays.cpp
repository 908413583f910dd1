#include "scene/rtrscene_arrays.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <mutex>
#include <type_traits>

#include <sys/mman.h>
#include <unistd.h>

#include <glm/geometric.hpp>

#include "cluster.h"
#include "core/parallel.hpp"

namespace rtr::rtrscene {
namespace {

using Fault = ReadFault;

template <class T>
T load(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

void checkFinite(const uint8_t* p, size_t at, int floats, const char* what) {
  for (int k = 0; k < floats; ++k)
    if (!std::isfinite(load<float>(p + 4 * k))) throw Fault{at + 4 * size_t(k), std::string(what) + " is not finite"};
}

// A piece of the second pass: copy one of a mesh's arrays out of the file, or check elements
// [first, first + count) of one (the checks read the file's bytes, not the copies, so they need not wait).
struct Job {
  uint32_t mesh;
  Stream stream;
  bool copy;
  size_t first, count, cost;
};

// The arrays are aligned in the file, and the file in memory (decodeRtrScene sees to it).
template <class T>
const T* as(const uint8_t* base, size_t at) {
  return reinterpret_cast<const T*>(base + at);
}

// assign copies without first zeroing the vectors (a resize would write every byte twice).
template <class T>
void copyTo(ViewOrVector<T>& v, const uint8_t* base, size_t at, size_t n) {
  v.writable().assign(as<T>(base, at), as<T>(base, at) + n);
}

// The storage a copy job will write: allocated, not yet touched.
template <class T>
std::span<uint8_t> reserve(ViewOrVector<T>& v, size_t n) {
  v.writable().reserve(n);
  return {reinterpret_cast<uint8_t*>(v.writable().data()), n * sizeof(T)};
}

std::span<uint8_t> reserveStream(Mesh& m, const MeshLayout& l, Stream s) {
  const size_t v = l.vertices;
  switch (s) {
    case kPositions: return reserve(m.positions, v);
    case kNormals: return reserve(m.normals, v);
    case kTexcoords: return reserve(m.texcoords, v);
    case kTexcoords1: return reserve(m.texcoords1, v);
    case kTangents: return reserve(m.tangents, v);
    case kColors: return reserve(m.colors, v);
    case kIndices: return reserve(m.indices, l.indices);
    default: return {};
  }
}

// An array made a view of the file's `n` elements at `at` where their bytes are its elements' (a
// little-endian host, the address aligned for T) and an owner keeps the bytes: no copy. False: copy it.
template <class T>
bool viewOf(ViewOrVector<T>& v, const uint8_t* base, size_t at, size_t n, const std::shared_ptr<const void>& owner) {
  static_assert(std::is_trivially_copyable_v<T>);
  const uint8_t* p = base + at;
  if (!owner || std::endian::native != std::endian::little || reinterpret_cast<uintptr_t>(p) % alignof(T) != 0) return false;
  v = ViewOrVector<T>::view({reinterpret_cast<const T*>(p), n}, owner);
  return true;
}

// The file's records are the structs' bytes (scene.hpp lays them out so).
static_assert(sizeof(Cluster) == 40 && offsetof(Cluster, radius) == 12 && offsetof(Cluster, coneAxis) == 16 &&
              offsetof(Cluster, coneCutoff) == 28 && offsetof(Cluster, firstTriangle) == 32 &&
              offsetof(Cluster, triangleCount) == 36);
static_assert(sizeof(LodCluster) == 96 && offsetof(LodCluster, error) == 12 && offsetof(LodCluster, center) == 16 &&
              offsetof(LodCluster, coneAxis) == 32 && offsetof(LodCluster, sphere) == 48 &&
              offsetof(LodCluster, parentSphere) == 64 && offsetof(LodCluster, parentError) == 80 &&
              offsetof(LodCluster, reserved) == 84);

bool viewStream(Mesh& m, const MeshLayout& l, Stream s, const uint8_t* base, const std::shared_ptr<const void>& owner) {
  const size_t v = l.vertices;
  switch (s) {
    case kPositions: return viewOf(m.positions, base, l.at[s], v, owner);
    case kNormals: return viewOf(m.normals, base, l.at[s], v, owner);
    case kTexcoords: return viewOf(m.texcoords, base, l.at[s], v, owner);
    case kTexcoords1: return viewOf(m.texcoords1, base, l.at[s], v, owner);
    case kTangents: return viewOf(m.tangents, base, l.at[s], v, owner);
    case kColors: return viewOf(m.colors, base, l.at[s], v, owner);
    case kIndices: return !(l.flags & kIndex16) && viewOf(m.indices, base, l.indexAt, l.indices, owner);  // 16-bit: widened
    case kClusters: return viewOf(m.clusters, base, l.clusterAt, l.clusters, owner);
    default: return false;
  }
}

// Makes the pages of [p, p + n) present and writable (MADV_POPULATE_WRITE, Linux 5.14); where the kernel
// lacks it the first writes fault them in as before.
void populate(uint8_t* p, size_t n) {
  static const size_t page = size_t(sysconf(_SC_PAGESIZE));
  const uintptr_t b = (reinterpret_cast<uintptr_t>(p) + page - 1) / page * page,
                  e = (reinterpret_cast<uintptr_t>(p) + n) / page * page;
#ifdef MADV_POPULATE_WRITE
  if (b < e) madvise(reinterpret_cast<void*>(b), e - b, MADV_POPULATE_WRITE);
#else
  (void)b, (void)e;
#endif
}

void copyStream(Mesh& m, const MeshLayout& l, Stream s, const uint8_t* base) {
  const size_t v = l.vertices, n = l.indices;
  switch (s) {
    case kPositions: copyTo(m.positions, base, l.at[s], v); break;
    case kNormals: copyTo(m.normals, base, l.at[s], v); break;
    case kTexcoords: copyTo(m.texcoords, base, l.at[s], v); break;
    case kTexcoords1: copyTo(m.texcoords1, base, l.at[s], v); break;
    case kTangents: copyTo(m.tangents, base, l.at[s], v); break;
    case kColors: copyTo(m.colors, base, l.at[s], v); break;
    case kIndices:
      if (l.flags & kIndex16) m.indices.writable().assign(as<uint16_t>(base, l.indexAt), as<uint16_t>(base, l.indexAt) + n);
      else copyTo(m.indices, base, l.indexAt, n);
      break;
    case kClusters:
    case kLodClusters:
    case kLodIndices: break;
  }
}

// Elements [first, end) of an array of T at p must pass `ok`, a test without branches so that the scan
// runs at memory speed; a block that fails is scanned again by `exact`, which throws the fault.
template <class T, class Ok, class Exact>
void scan(const uint8_t* p, size_t first, size_t end, Ok ok, Exact exact) {
  constexpr size_t kBlock = 1024;
  for (size_t b = first; b < end; b += kBlock) {
    const size_t e = std::min(end, b + kBlock);
    bool good = true;
    for (size_t k = b; k < e; ++k) good &= ok(load<T>(p + k * sizeof(T)));
    if (!good)
      for (size_t k = b; k < e; ++k) exact(k, load<T>(p + k * sizeof(T)));
  }
}

template <class Index>
void checkIndices(const MeshLayout& l, const uint8_t* base, uint32_t i, size_t first, size_t end) {
  scan<Index>(
      base + l.indexAt, first, end, [&](Index v) { return v < l.vertices; },
      [&](size_t k, Index v) {
        if (v >= l.vertices)
          throw Fault{l.indexAt + k * sizeof(Index), meshName(i) + ": index " + std::to_string(v) + " out of range (" +
                                                         std::to_string(l.vertices) + " vertices)"};
      });
}

// Finite when every component times 0 is 0 (an infinity or a NaN gives NaN): no branch, no overflow.
template <int N>
bool allFinite(glm::vec<N, float> v) {
  float z = 0.0f;
  for (int c = 0; c < N; ++c) z += v[c] * 0.0f;
  return z == 0.0f;
}

template <int N>
void checkFiniteArray(const uint8_t* base, size_t at, size_t first, size_t end, const std::string& what) {
  using V = glm::vec<N, float>;
  scan<V>(base + at, first, end, allFinite<N>, [&](size_t k, V v) {
    if (!allFinite<N>(v)) throw Fault{at + k * sizeof(V), what + " is not finite"};
  });
}

void checkArray(const Mesh& m, const MeshLayout& l, const uint8_t* base, uint32_t i, Stream s, size_t first, size_t end) {
  const Bounds& b = m.bounds;  // finite (read as such): a NaN or an infinity is never inside
  auto inside = [&](glm::vec3 p) {
    return (p.x >= b.min.x) & (p.y >= b.min.y) & (p.z >= b.min.z) & (p.x <= b.max.x) & (p.y <= b.max.y) & (p.z <= b.max.z);
  };
  const size_t at = s < kVertexStreams ? l.at[s] : 0;
  switch (s) {
    case kPositions:
      return scan<glm::vec3>(base + at, first, end, inside, [&](size_t k, glm::vec3 p) {
        if (!allFinite<3>(p)) throw Fault{at + k * 12, meshName(i) + ": position " + std::to_string(k) + " is not finite"};
        if (!inside(p))
          throw Fault{at + k * 12, meshName(i) + ": position " + std::to_string(k) + " lies outside the mesh bounds"};
      });
    case kNormals: return checkFiniteArray<3>(base, at, first, end, meshName(i) + ": a normal");
    case kTexcoords: return checkFiniteArray<2>(base, at, first, end, meshName(i) + ": a texcoord");
    case kTexcoords1: return checkFiniteArray<2>(base, at, first, end, meshName(i) + ": a second-set texcoord");
    case kTangents: return checkFiniteArray<4>(base, at, first, end, meshName(i) + ": a tangent");
    case kColors: return checkFiniteArray<4>(base, at, first, end, meshName(i) + ": a vertex colour");
    case kIndices:
      return l.flags & kIndex16 ? checkIndices<uint16_t>(l, base, i, first, end) : checkIndices<uint32_t>(l, base, i, first, end);
    case kClusters:
    case kLodClusters:
    case kLodIndices: return;
  }
}

// Clusters [first, end) of mesh i, read into `out` (null: m.clusters is a view of them). They must tile the mesh's triangles in order, each
// within the GPU's limits, its sphere holding its vertices: the culling pass and the compute rasteriser
// trust them.
template <class Index>
void checkClusters(Cluster* out, const MeshLayout& l, const uint8_t* base, uint32_t i, size_t first, size_t end) {
  static_assert(CLUSTER_MAX_VERTICES < 128, "the vertex set below holds 128");
  const uint32_t triangles = l.indices / 3;
  auto fault = [&](size_t at, size_t k, const std::string& what) {
    throw Fault{at, meshName(i) + ": cluster " + std::to_string(k) + ": " + what};
  };
  // Where cluster k must start: where the one before it ended (that one's faults are its own piece's).
  uint64_t next = 0;
  if (first > 0) {
    const uint8_t* prev = base + l.clusterAt + (first - 1) * 40;
    next = uint64_t(load<uint32_t>(prev + 32)) + load<uint32_t>(prev + 36);
  }
  for (size_t k = first; k < end; ++k) {
    const size_t cAt = l.clusterAt + k * 40;
    const uint8_t* p = base + cAt;
    checkFinite(p, cAt, 4, "a cluster's sphere");
    checkFinite(p + 16, cAt + 16, 4, "a cluster's cone");
    Cluster c;
    c.center = load<glm::vec3>(p);
    c.radius = load<float>(p + 12);
    c.coneAxis = load<glm::vec3>(p + 16);
    c.coneCutoff = load<float>(p + 28);
    c.firstTriangle = load<uint32_t>(p + 32);
    c.triangleCount = load<uint32_t>(p + 36);
    if (!(c.radius >= 0.0f)) fault(cAt + 12, k, "negative radius");
    // A cone that culls (cutoff < 1) has a unit axis and a cutoff >= 0 (meshoptimizer's); others would cull
    // clusters that face the eye.
    if (c.coneCutoff < 1.0f && (c.coneCutoff < 0.0f || std::abs(glm::length(c.coneAxis) - 1.0f) > 1e-3f))
      fault(cAt + 16, k, "cone axis not a unit vector or cutoff below 0");
    if (c.firstTriangle != next)
      fault(cAt + 32, k,
            "first triangle " + std::to_string(c.firstTriangle) + " is not " + std::to_string(next) +
                " (clusters tile the triangles in order)");
    // Past the end only when the cluster before is damaged: its piece reports that, at a lower offset.
    const uint32_t left = next <= triangles ? triangles - uint32_t(next) : 0;
    if (c.triangleCount < 1 || c.triangleCount > CLUSTER_MAX_TRIANGLES || c.triangleCount > left)
      fault(cAt + 36, k,
            "triangle count " + std::to_string(c.triangleCount) + " not in 1.." +
                std::to_string(std::min<uint32_t>(CLUSTER_MAX_TRIANGLES, left)));
    next += c.triangleCount;
    if (out) out[k] = c;
    // Its distinct vertices gathered first (a small open-addressed set: at most 65 of 128 slots filled),
    // then their positions read together: they are scattered over the array, the loads overlap.
    uint32_t seen[128], vertices[CLUSTER_MAX_VERTICES];
    std::fill(std::begin(seen), std::end(seen), ~0u);
    uint32_t distinct = 0;
    for (size_t t = size_t(c.firstTriangle) * 3; t < size_t(next) * 3; ++t) {
      const uint32_t v = load<Index>(base + l.indexAt + t * sizeof(Index));
      if (v >= l.vertices) continue;  // refused by the index check, at a lower offset
      uint32_t h = (v * 0x9E3779B1u) >> 25;
      while (seen[h] != v && seen[h] != ~0u) h = (h + 1) & 127;
      if (seen[h] == v) continue;
      seen[h] = v;
      if (distinct == CLUSTER_MAX_VERTICES) fault(cAt, k, "more than " + std::to_string(CLUSTER_MAX_VERTICES) + " vertices");
      vertices[distinct++] = v;
    }
    const float slack = c.radius * 1e-4f + 1e-6f * (std::abs(c.center.x) + std::abs(c.center.y) + std::abs(c.center.z));
    for (uint32_t j = 0; j < distinct; ++j)
      if (!(glm::length(load<glm::vec3>(base + l.at[kPositions] + size_t(vertices[j]) * 12) - c.center) <= c.radius + slack))
        fault(cAt, k, "vertex " + std::to_string(vertices[j]) + " lies outside its bounding sphere");
  }
  if (end == l.clusters && next != triangles)
    throw Fault{l.clusterHeaderAt,
                meshName(i) + ": clusters cover " + std::to_string(next) + " of " + std::to_string(triangles) + " triangles"};
}

}  // namespace

void placeClusters(Mesh& m, const MeshLayout& l, const uint8_t* file, const std::shared_ptr<const void>& owner) {
  if (!viewStream(m, l, kClusters, file, owner)) m.clusters.resize(l.clusters);
}

// The second pass: every array viewed or copied out of the file and every value, index and cluster
// checked, the hierarchies' (`lods`, CLOD) too, in pieces on `threads` threads, biggest first.
void readArrays(std::span<const uint8_t> bytes, Scene& scene, const std::vector<MeshLayout>& layout,
                const std::vector<LodLayout>& lods, unsigned threads, const ByteReader& r,
                const std::shared_ptr<const void>& owner) {
  constexpr size_t kPiece = size_t(1) << 18, kClusterPiece = 2048, kLodPiece = 4096;
  const uint8_t* base = bytes.data();
  // Where the file's bytes are the arrays' (and `owner` keeps them), the arrays are views of them, set
  // now: the checks below read the file either way, and a fault throws the scene away.
  std::vector<Cluster*> clustersOut(layout.size());
  std::vector<LodCluster*> lodOut(lods.size());
  std::vector<Job> jobs;
  for (uint32_t i = 0; i < layout.size(); ++i) {
    const MeshLayout& l = layout[i];
    Mesh& m = scene.meshes[i];
    for (uint8_t s = kPositions; s <= kIndices; ++s) {
      const size_t count = l.count(Stream(s)), size = l.elementSize(Stream(s));
      if (count == 0) continue;
      if (!viewStream(m, l, Stream(s), base, owner))
        jobs.push_back({i, Stream(s), true, 0, count, 2 * count * size});  // writes cost more: fresh pages
      for (size_t f = 0; f < count; f += kPiece) {
        const size_t n = std::min(kPiece, count - f);
        jobs.push_back({i, Stream(s), false, f, n, n * size});
      }
    }
    if (l.clusters && !m.clusters.isView()) clustersOut[i] = m.clusters.writable().data();  // placeClusters sized it
    for (size_t f = 0; f < l.clusters; f += kClusterPiece) {
      const size_t n = std::min<size_t>(kClusterPiece, l.clusters - f);
      jobs.push_back({i, kClusters, false, f, n, n * 1000});  // ~124 triangles' indices and ~64 positions each
    }
  }
  std::vector<bool> lodCopied(lods.size());
  for (uint32_t j = 0; j < lods.size(); ++j) {  // their jobs' `mesh` is the index in `lods`
    const LodLayout& l = lods[j];
    ClusterLod& lod = scene.meshes[l.mesh].lod;
    if (l.indexCount && !viewOf(lod.indices, base, l.indicesAt, l.indexCount, owner))
      jobs.push_back({j, kLodIndices, true, 0, l.indexCount, 8 * size_t(l.indexCount)});
    lodCopied[j] = !viewOf(lod.clusters, base, l.clustersAt, l.count, owner);
    for (size_t f = 0; f < l.indexCount; f += kPiece) {
      const size_t n = std::min<size_t>(kPiece, l.indexCount - f);
      jobs.push_back({j, kLodIndices, false, f, n, 4 * n});
    }
    for (size_t f = 0; f < l.count; f += kLodPiece) {
      const size_t n = std::min<size_t>(kLodPiece, l.count - f);
      jobs.push_back({j, kLodClusters, false, f, n, n * 200});  // a 96-byte record read, written and checked
    }
  }
  std::stable_sort(jobs.begin(), jobs.end(), [](const Job& a, const Job& b) { return a.cost > b.cost; });
  // A large copy's time went mostly to its fresh pages' faults (the kernel clearing each page), on the
  // copying thread alone, as did the hierarchies' records made on one thread: each array copied is
  // allocated first, its pages made present in pieces on all cores beside the checks, then the copies
  // and the hierarchies' records (their vectors sized in between, into present pages) run.
  constexpr size_t kPagePiece = size_t(4) << 20;
  std::vector<std::span<uint8_t>> pages;
  auto addPages = [&](std::span<uint8_t> a) {
    for (size_t b = 0; b < a.size(); b += kPagePiece) pages.push_back(a.subspan(b, std::min(kPagePiece, a.size() - b)));
  };
  const auto second =
      std::stable_partition(jobs.begin(), jobs.end(), [](const Job& j) { return !j.copy && j.stream != kLodClusters; });
  for (auto j = second; j != jobs.end(); ++j) {
    if (!j->copy) continue;
    Mesh& m = scene.meshes[j->stream == kLodIndices ? lods[j->mesh].mesh : j->mesh];
    addPages(j->stream == kLodIndices ? reserve(m.lod.indices, j->count) : reserveStream(m, layout[j->mesh], j->stream));
  }
  for (uint32_t j = 0; j < lods.size(); ++j)
    if (lodCopied[j]) addPages(reserve(scene.meshes[lods[j].mesh].lod.clusters, lods[j].count));
  const size_t firstPhase = size_t(second - jobs.begin());
  Fault first;
  std::mutex firstMutex;
  auto run = [&](const Job& job) {
    const bool lod = job.stream == kLodClusters || job.stream == kLodIndices;
    const uint32_t mesh = lod ? lods[job.mesh].mesh : job.mesh;
    Mesh& m = scene.meshes[mesh];
    const MeshLayout& l = layout[mesh];
    const size_t end = job.first + job.count;
    try {
      if (job.copy && job.stream == kLodIndices) copyTo(m.lod.indices, base, lods[job.mesh].indicesAt, job.count);
      else if (job.copy) copyStream(m, l, job.stream, base);
      else if (job.stream == kLodIndices) checkLodIndices(lods[job.mesh], base, l.vertices, job.first, end);
      else if (job.stream == kLodClusters)
        readLodClusters(m, lodOut[job.mesh], lods[job.mesh], base, l.clusterAt, l.indices / 3, job.first, end);
      else if (job.stream == kClusters && (l.flags & kIndex16))
        checkClusters<uint16_t>(clustersOut[mesh], l, base, mesh, job.first, end);
      else if (job.stream == kClusters) checkClusters<uint32_t>(clustersOut[mesh], l, base, mesh, job.first, end);
      else checkArray(m, l, base, mesh, job.stream, job.first, end);
    } catch (Fault& f) {
      std::lock_guard lock(firstMutex);
      if (f.at < first.at) first = std::move(f);
    }
  };
  parallelFor(pages.size() + firstPhase, threads, [&](size_t j) {
    if (j < pages.size()) populate(pages[j].data(), pages[j].size());
    else run(jobs[j - pages.size()]);
  });
  for (uint32_t j = 0; j < lods.size(); ++j) {
    if (!lodCopied[j]) continue;
    std::vector<LodCluster>& v = scene.meshes[lods[j].mesh].lod.clusters.writable();
    v.resize(lods[j].count);
    lodOut[j] = v.data();
  }
  const bool faulty = first.at != SIZE_MAX;  // no copies then; the records may still hold a lower fault
  parallelFor(jobs.size() - firstPhase, threads, [&](size_t j) {
    if (!(faulty && jobs[firstPhase + j].copy)) run(jobs[firstPhase + j]);
  });
  if (first.at != SIZE_MAX) r.failAt(first.at, first.what);
}

}  // namespace rtr::rtrscene
