#include "scene/rtrscene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <vector>

#include <glm/geometric.hpp>

#include "cluster.h"
#include "scene/binio.hpp"
#include "core/parallel.hpp"

namespace rtr {
namespace {

constexpr char kMagic[8] = {'R', 'T', 'R', 'S', 'C', 'E', 'N', 'E'};
constexpr size_t kHeaderSize = 80;
constexpr size_t kAlign = 16;
constexpr uint32_t kMaxString = 32768;

constexpr uint32_t kHasView = 1u << 0;  // header flags
constexpr uint32_t kLightFalloff = 1u << 0;  // light flags
constexpr uint32_t kHasNormals = 1u << 0, kHasTexcoords = 1u << 1, kIndex16 = 1u << 2;  // mesh flags
constexpr uint32_t kKnownMaterialFlags = kMaterialAlphaMasked | kMaterialDoubleSided | kMaterialLight;

void writeString(ByteWriter& w, const std::string& s) {
  if (s.size() >= kMaxString) throw Error("string longer than 32767 bytes: " + s.substr(0, 64));
  w.u32(uint32_t(s.size()));
  w.bytes(s.data(), s.size());
  w.pad(4);
}

void writeVec(ByteWriter& w, const glm::vec3& v) { w.f32(v.x); w.f32(v.y); w.f32(v.z); }

std::string readString(ByteReader& r, const char* what) {
  const size_t at = r.pos();
  const uint32_t n = r.u32(what);
  if (n >= kMaxString) r.failAt(at, std::string(what) + " length " + std::to_string(n) + " is not below 32768");
  std::string_view s = r.view(n, what);
  // Names are bytes, as the OBJ/MTL files they come from (Latin-1 names exist); only NUL is refused.
  if (s.find('\0') != std::string_view::npos) r.failAt(at + 4, std::string(what) + " contains a NUL byte");
  r.align(4, what);
  return std::string(s);
}

float readFinite(ByteReader& r, const char* what) {
  const size_t at = r.pos();
  const float f = r.f32(what);
  if (!std::isfinite(f)) r.failAt(at, std::string(what) + " is not finite");
  return f;
}

glm::vec3 readVec(ByteReader& r, const char* what) {
  glm::vec3 v;
  for (int i = 0; i < 3; ++i) v[i] = readFinite(r, what);
  return v;
}

// Where a mesh's arrays and clusters lie in the file: found by the first pass over the records, copied out
// and checked by the second, on all cores.
struct MeshLayout {
  uint32_t flags = 0, vertices = 0, indices = 0, clusters = 0;
  size_t posAt = 0, normalAt = 0, texcoordAt = 0, indexAt = 0, clusterHeaderAt = 0, clusterAt = 0;
};

// A fault found by a worker. Of several, the one at the lowest offset is reported, so the message does
// not depend on the thread count.
struct Fault {
  size_t at = SIZE_MAX;
  std::string what;
};

template <class T>
T load(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

std::string meshName(uint32_t i) { return "mesh " + std::to_string(i); }

void checkFinite(const uint8_t* p, size_t at, int floats, const char* what) {
  for (int k = 0; k < floats; ++k)
    if (!std::isfinite(load<float>(p + 4 * k))) throw Fault{at + 4 * size_t(k), std::string(what) + " is not finite"};
}

enum Stream : uint8_t { kPositions, kNormals, kTexcoords, kIndices, kClusters };

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
void copyStream(Mesh& m, const MeshLayout& l, Stream s, const uint8_t* base) {
  const size_t v = l.vertices, n = l.indices;
  switch (s) {
    case kPositions: m.positions.assign(as<glm::vec3>(base, l.posAt), as<glm::vec3>(base, l.posAt) + v); break;
    case kNormals: m.normals.assign(as<glm::vec3>(base, l.normalAt), as<glm::vec3>(base, l.normalAt) + v); break;
    case kTexcoords: m.texcoords.assign(as<glm::vec2>(base, l.texcoordAt), as<glm::vec2>(base, l.texcoordAt) + v); break;
    case kIndices:
      if (l.flags & kIndex16)
        m.indices.assign(as<uint16_t>(base, l.indexAt), as<uint16_t>(base, l.indexAt) + n);
      else
        m.indices.assign(as<uint32_t>(base, l.indexAt), as<uint32_t>(base, l.indexAt) + n);
      break;
    case kClusters: break;
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
  scan<Index>(base + l.indexAt, first, end, [&](Index v) { return v < l.vertices; }, [&](size_t k, Index v) {
    if (v >= l.vertices)
      throw Fault{l.indexAt + k * sizeof(Index),
                  meshName(i) + ": index " + std::to_string(v) + " out of range (" + std::to_string(l.vertices) + " vertices)"};
  });
}

void checkArray(const Mesh& m, const MeshLayout& l, const uint8_t* base, uint32_t i, Stream s, size_t first, size_t end) {
  const Bounds& b = m.bounds;  // finite (read as such): a NaN or an infinity is never inside
  auto inside = [&](glm::vec3 p) {
    return (p.x >= b.min.x) & (p.y >= b.min.y) & (p.z >= b.min.z) & (p.x <= b.max.x) & (p.y <= b.max.y) & (p.z <= b.max.z);
  };
  auto finite = [](float sum) { return std::abs(sum) <= std::numeric_limits<float>::max(); };  // NaN compares false
  switch (s) {
    case kPositions:
      return scan<glm::vec3>(base + l.posAt, first, end, inside, [&](size_t k, glm::vec3 p) {
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
          throw Fault{l.posAt + k * 12, meshName(i) + ": position " + std::to_string(k) + " is not finite"};
        if (!inside(p)) throw Fault{l.posAt + k * 12, meshName(i) + ": position " + std::to_string(k) + " lies outside the mesh bounds"};
      });
    case kNormals:
      return scan<glm::vec3>(base + l.normalAt, first, end, [&](glm::vec3 n) { return finite(n.x + n.y + n.z); },
                             [&](size_t k, glm::vec3 n) {
                               if (!finite(n.x + n.y + n.z)) throw Fault{l.normalAt + k * 12, meshName(i) + ": a normal is not finite"};
                             });
    case kTexcoords:
      return scan<glm::vec2>(base + l.texcoordAt, first, end, [&](glm::vec2 t) { return finite(t.x + t.y); },
                             [&](size_t k, glm::vec2 t) {
                               if (!finite(t.x + t.y)) throw Fault{l.texcoordAt + k * 8, meshName(i) + ": a texcoord is not finite"};
                             });
    case kIndices:
      return l.flags & kIndex16 ? checkIndices<uint16_t>(l, base, i, first, end) : checkIndices<uint32_t>(l, base, i, first, end);
    case kClusters: return;
  }
}

// Clusters [first, end) of mesh i, read into m.clusters. They must tile the mesh's triangles in order, each
// within the GPU's limits, its sphere holding its vertices: the culling pass and the compute rasteriser
// trust them.
template <class Index>
void checkClusters(Mesh& m, const MeshLayout& l, const uint8_t* base, uint32_t i, size_t first, size_t end) {
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
    Cluster& c = m.clusters[k];
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
      fault(cAt + 32, k, "first triangle " + std::to_string(c.firstTriangle) + " is not " + std::to_string(next) +
                             " (clusters tile the triangles in order)");
    // Past the end only when the cluster before is damaged: its piece reports that, at a lower offset.
    const uint32_t left = next <= triangles ? triangles - uint32_t(next) : 0;
    if (c.triangleCount < 1 || c.triangleCount > CLUSTER_MAX_TRIANGLES || c.triangleCount > left)
      fault(cAt + 36, k, "triangle count " + std::to_string(c.triangleCount) + " not in 1.." +
                             std::to_string(std::min<uint32_t>(CLUSTER_MAX_TRIANGLES, left)));
    next += c.triangleCount;
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
      if (!(glm::length(load<glm::vec3>(base + l.posAt + size_t(vertices[j]) * 12) - c.center) <= c.radius + slack))
        fault(cAt, k, "vertex " + std::to_string(vertices[j]) + " lies outside its bounding sphere");
  }
  if (end == l.clusters && next != triangles)
    throw Fault{l.clusterHeaderAt, meshName(i) + ": clusters cover " + std::to_string(next) + " of " +
                                       std::to_string(triangles) + " triangles"};
}

// The second pass: every array copied out of the file and every value, index and cluster checked, in
// pieces on `threads` threads, biggest first.
void readArrays(std::span<const uint8_t> bytes, Scene& scene, const std::vector<MeshLayout>& layout,
                unsigned threads, const ByteReader& r) {
  constexpr size_t kPiece = size_t(1) << 18, kClusterPiece = 2048;
  std::vector<Job> jobs;
  for (uint32_t i = 0; i < layout.size(); ++i) {
    const MeshLayout& l = layout[i];
    const size_t counts[] = {l.vertices, l.flags & kHasNormals ? l.vertices : 0u, l.flags & kHasTexcoords ? l.vertices : 0u,
                             l.indices};
    const size_t sizes[] = {12, 12, 8, size_t(l.flags & kIndex16 ? 2 : 4)};
    for (uint8_t s = kPositions; s <= kIndices; ++s) {
      if (counts[s] == 0) continue;
      jobs.push_back({i, Stream(s), true, 0, counts[s], 2 * counts[s] * sizes[s]});  // writes cost more: fresh pages
      for (size_t f = 0; f < counts[s]; f += kPiece) {
        const size_t n = std::min(kPiece, counts[s] - f);
        jobs.push_back({i, Stream(s), false, f, n, n * sizes[s]});
      }
    }
    for (size_t f = 0; f < l.clusters; f += kClusterPiece) {
      const size_t n = std::min<size_t>(kClusterPiece, l.clusters - f);
      jobs.push_back({i, kClusters, false, f, n, n * 1000});  // ~124 triangles' indices and ~64 positions each
    }
  }
  std::stable_sort(jobs.begin(), jobs.end(), [](const Job& a, const Job& b) { return a.cost > b.cost; });
  Fault first;
  std::mutex firstMutex;
  parallelFor(jobs.size(), threads, [&](size_t j) {
    const Job& job = jobs[j];
    Mesh& m = scene.meshes[job.mesh];
    const MeshLayout& l = layout[job.mesh];
    try {
      if (job.copy)
        copyStream(m, l, job.stream, bytes.data());
      else if (job.stream == kClusters && (l.flags & kIndex16))
        checkClusters<uint16_t>(m, l, bytes.data(), job.mesh, job.first, job.first + job.count);
      else if (job.stream == kClusters)
        checkClusters<uint32_t>(m, l, bytes.data(), job.mesh, job.first, job.first + job.count);
      else
        checkArray(m, l, bytes.data(), job.mesh, job.stream, job.first, job.first + job.count);
    } catch (Fault& f) {
      std::lock_guard lock(firstMutex);
      if (f.at < first.at) first = std::move(f);
    }
  });
  if (first.at != SIZE_MAX) r.failAt(first.at, first.what);
}

}  // namespace

std::string encodeRtrScene(const Scene& scene, uint32_t version) {
  if (version < 1 || version > kRtrSceneVersion || (version < 2 && !scene.lights.empty()))
    throw Error("cannot encode .rtrscene version " + std::to_string(version) + (scene.lights.empty() ? "" : " with lights"));
  ByteWriter w;
  w.bytes(kMagic, 8);
  w.u32(version);
  w.u32(scene.defaultView ? kHasView : 0);
  w.u32(uint32_t(scene.textures.size()));
  w.u32(uint32_t(scene.materials.size()));
  w.u32(uint32_t(scene.meshes.size()));
  w.u32(uint32_t(scene.lights.size()));
  w.pod(uint64_t(0));  // payload size, patched below
  w.pod(uint64_t(0));  // checksum, patched below
  const CameraPose view = scene.defaultView.value_or(CameraPose{});
  writeVec(w, view.position);
  w.f32(view.yawDeg);
  w.f32(view.pitchDeg);
  w.pad(kAlign);

  for (const Light& l : scene.lights) {  // 80 bytes each
    w.u32(uint32_t(l.kind));
    w.u32(l.falloff ? kLightFalloff : 0);
    for (const glm::vec3& v : {l.position, l.color, l.corner, l.edge1, l.edge2, l.normal}) writeVec(w, v);
  }
  for (const Texture& t : scene.textures) {
    w.u8(t.srgb ? 1 : 0);
    w.u8(t.channels);
    w.pod(uint16_t(0));
    writeString(w, t.path.generic_string());
  }
  w.pad(kAlign);
  for (const Material& m : scene.materials) {
    w.u32(m.flags);
    writeString(w, m.name);
    writeVec(w, m.baseColor);
    w.f32(m.roughness);
    w.f32(m.metalness);
    writeVec(w, m.emissive);
    writeVec(w, m.ka);
    writeVec(w, m.kd);
    writeVec(w, m.ks);
    writeVec(w, m.ke);
    w.f32(m.ns);
    w.f32(m.mirror);
    w.f32(m.ior);
    w.f32(m.transparency);
    for (uint32_t s = 0; s < kCourseSlotCount; ++s) w.u32(m.textures[s]);
  }
  w.pad(kAlign);
  for (const Mesh& m : scene.meshes) {
    const size_t v = m.positions.size();
    if ((!m.normals.empty() && m.normals.size() != v) || (!m.texcoords.empty() && m.texcoords.size() != v))
      throw Error("mesh '" + m.name + "': attribute counts differ");
    const bool small = v <= 0x10000;
    w.u32(m.material);
    w.u32((m.normals.empty() ? 0 : kHasNormals) | (m.texcoords.empty() ? 0 : kHasTexcoords) | (small ? kIndex16 : 0));
    w.u32(uint32_t(v));
    w.u32(uint32_t(m.indices.size()));
    writeVec(w, v ? m.bounds.min : glm::vec3(0.0f));  // an empty mesh's bounds are infinite: store zeros
    writeVec(w, v ? m.bounds.max : glm::vec3(0.0f));
    writeString(w, m.name);
    w.pad(kAlign);
    w.array(m.positions);
    w.pad(kAlign);
    w.array(m.normals);
    w.pad(kAlign);
    w.array(m.texcoords);
    w.pad(kAlign);
    if (small)
      w.array(std::vector<uint16_t>(m.indices.begin(), m.indices.end()));
    else
      w.array(m.indices);
    w.pad(kAlign);
    // Version 3: the clusters (zero: none stored, built at load).
    if (version < 3) continue;
    w.u32(uint32_t(m.clusters.size()));
    w.data().append(12, '\0');
    for (const Cluster& c : m.clusters) {  // 40 bytes each
      writeVec(w, c.center);
      w.f32(c.radius);
      writeVec(w, c.coneAxis);
      w.f32(c.coneCutoff);
      w.u32(c.firstTriangle);
      w.u32(c.triangleCount);
    }
    w.pad(kAlign);
  }
  std::string& out = w.data();
  const uint64_t payload = out.size() - kHeaderSize;
  const std::span<const uint8_t> payloadBytes{reinterpret_cast<const uint8_t*>(out.data()) + kHeaderSize, payload};
  const uint64_t sum = version >= 4 ? pieceChecksum64(payloadBytes) : checksum64(payloadBytes);
  std::memcpy(out.data() + 32, &payload, 8);
  std::memcpy(out.data() + 40, &sum, 8);
  return std::move(out);
}

Scene decodeRtrScene(std::span<const uint8_t> bytes, const std::string& file, unsigned threads) {
  if (!bytes.empty() && reinterpret_cast<uintptr_t>(bytes.data()) % alignof(uint32_t) != 0) {  // arrays read in place
    std::vector<uint32_t> aligned((bytes.size() + 3) / 4);
    std::memcpy(aligned.data(), bytes.data(), bytes.size());
    return decodeRtrScene({reinterpret_cast<const uint8_t*>(aligned.data()), bytes.size()}, file, threads);
  }
  if (threads == 0 && bytes.size() < (size_t(4) << 20)) threads = 1;  // a small file: starting threads costs more
  ByteReader r(bytes, file);
  char magic[8];
  r.raw(magic, 8, "the header");
  if (std::memcmp(magic, kMagic, 8) != 0) r.failAt(0, "not an .rtrscene file (magic mismatch)");
  const uint32_t version = r.u32("the header");
  if (version < 1 || version > kRtrSceneVersion)
    r.failAt(8, "unsupported version " + std::to_string(version) + " (this build reads " + std::to_string(kRtrSceneVersion) + ")");
  const uint32_t flags = r.u32("the header");
  if (flags & ~uint32_t(kHasView)) r.failAt(12, "unknown header flags");
  const uint32_t texCount = r.u32("the header"), matCount = r.u32("the header"), meshCount = r.u32("the header");
  const uint32_t lightCount = r.u32("the header");
  if (version == 1 && lightCount != 0) r.failAt(28, "reserved field is not 0");
  const uint64_t payload = r.pod<uint64_t>("the header");
  const uint64_t sum = r.pod<uint64_t>("the header");
  Scene scene;
  CameraPose view;
  view.position = readVec(r, "the default view");
  view.yawDeg = readFinite(r, "the default view");
  view.pitchDeg = readFinite(r, "the default view");
  if (flags & kHasView) scene.defaultView = view;
  r.align(kAlign, "the header");
  if (payload != bytes.size() - kHeaderSize)
    r.failAt(32, "payload size " + std::to_string(payload) + " does not match the file (" +
                     std::to_string(bytes.size() - kHeaderSize) + " bytes after the header): truncated or padded");
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
  (void)sum;  // fuzz builds only: a mutated input almost never carries a valid checksum, so the decoder went unfuzzed
#else
  // Version 4's checksum runs on all cores; older files are summed on one.
  const std::span<const uint8_t> payloadBytes = bytes.subspan(kHeaderSize);
  if ((version >= 4 ? pieceChecksum64(payloadBytes, threads) : checksum64(payloadBytes)) != sum)
    r.failAt(40, "checksum mismatch: the payload is corrupt");
#endif

  // Each record has a minimum size; a count that cannot fit is refused before anything is allocated.
  if (uint64_t(lightCount) * 80 > r.remaining()) r.failAt(28, "light count " + std::to_string(lightCount) + " cannot fit in the file");
  if (uint64_t(texCount) * 8 > r.remaining()) r.failAt(16, "texture count " + std::to_string(texCount) + " cannot fit in the file");
  if (uint64_t(matCount) * 128 > r.remaining()) r.failAt(20, "material count " + std::to_string(matCount) + " cannot fit in the file");
  if (uint64_t(meshCount) * 64 > r.remaining()) r.failAt(24, "mesh count " + std::to_string(meshCount) + " cannot fit in the file");

  scene.lights.resize(lightCount);
  for (Light& l : scene.lights) {
    const size_t at = r.pos();
    const uint32_t kind = r.u32("a light record"), lflags = r.u32("a light record");
    if (kind > uint32_t(Light::Kind::Headlight)) r.failAt(at, "unknown light kind " + std::to_string(kind));
    if (lflags & ~kLightFalloff) r.failAt(at + 4, "unknown light flags");
    l.kind = Light::Kind(kind);
    l.falloff = (lflags & kLightFalloff) != 0;
    for (glm::vec3* v : {&l.position, &l.color, &l.corner, &l.edge1, &l.edge2, &l.normal}) *v = readVec(r, "a light");
  }

  scene.textures.resize(texCount);
  for (Texture& t : scene.textures) {
    const size_t at = r.pos();
    const uint8_t srgb = r.u8("a texture record"), ch = r.u8("a texture record");
    r.skip(2, "a texture record");
    if (srgb > 1) r.failAt(at, "texture sRGB flag " + std::to_string(srgb) + " is neither 0 nor 1");
    if (ch < 1 || ch > 4) r.failAt(at + 1, "texture channel count " + std::to_string(ch) + " not in 1..4");
    t.srgb = srgb == 1;
    t.channels = ch;
    t.path = readString(r, "a texture path");
    if (t.path.empty()) r.failAt(at + 4, "empty texture path");
  }
  r.align(kAlign, "the texture table");

  scene.materials.resize(matCount);
  for (Material& m : scene.materials) {
    const size_t at = r.pos();
    m.flags = r.u32("a material record");
    if (m.flags & ~kKnownMaterialFlags) r.failAt(at, "unknown material flags");
    m.name = readString(r, "a material name");
    m.baseColor = readVec(r, "a material factor");
    m.roughness = readFinite(r, "a material factor");
    m.metalness = readFinite(r, "a material factor");
    m.emissive = readVec(r, "a material factor");
    m.ka = readVec(r, "a material factor");
    m.kd = readVec(r, "a material factor");
    m.ks = readVec(r, "a material factor");
    m.ke = readVec(r, "a material factor");
    m.ns = readFinite(r, "a material factor");
    m.mirror = readFinite(r, "a material factor");
    m.ior = readFinite(r, "a material factor");
    m.transparency = readFinite(r, "a material factor");
    for (uint32_t s = 0; s < kCourseSlotCount; ++s) {
      uint32_t& id = m.textures[s];
      const size_t idAt = r.pos();
      id = r.u32("a material texture index");
      if (id != kNoTexture && id >= texCount)
        r.failAt(idAt, "texture index " + std::to_string(id) + " out of range (" + std::to_string(texCount) + " textures)");
    }
  }
  r.align(kAlign, "the material table");

  // First pass: the mesh records, their sizes and where their arrays lie; the arrays are read after.
  scene.meshes.resize(meshCount);
  std::vector<MeshLayout> layout(meshCount);
  for (uint32_t i = 0; i < meshCount; ++i) {
    Mesh& m = scene.meshes[i];
    MeshLayout& l = layout[i];
    const std::string which = meshName(i);
    const size_t at = r.pos();
    m.material = r.u32("a mesh record");
    if (m.material >= matCount) r.failAt(at, which + ": material index " + std::to_string(m.material) + " out of range");
    const uint32_t mf = r.u32("a mesh record");
    if (mf & ~uint32_t(kHasNormals | kHasTexcoords | kIndex16)) r.failAt(at + 4, which + ": unknown mesh flags");
    const uint32_t v = r.u32("a mesh record"), n = r.u32("a mesh record");
    if (n % 3 != 0) r.failAt(at + 12, which + ": index count " + std::to_string(n) + " is not a multiple of 3");
    if ((mf & kIndex16) && v > 0x10000) r.failAt(at + 4, which + ": 16-bit indices with more than 65536 vertices");
    const uint64_t need = uint64_t(v) * (12 + (mf & kHasNormals ? 12 : 0) + (mf & kHasTexcoords ? 8 : 0)) +
                          uint64_t(n) * (mf & kIndex16 ? 2 : 4);
    if (need > r.remaining())
      r.failAt(at + 8, which + ": " + std::to_string(v) + " vertices and " + std::to_string(n) + " indices cannot fit in the " +
                           std::to_string(r.remaining()) + " bytes left");
    m.bounds.min = readVec(r, "mesh bounds");
    m.bounds.max = readVec(r, "mesh bounds");
    if (v == 0) m.bounds = Bounds{};
    m.name = readString(r, "a mesh name");
    r.align(kAlign, "a mesh record");
    l.flags = mf;
    l.vertices = v;
    l.indices = n;
    l.posAt = r.skipArray(v, 12, "positions");
    r.align(kAlign, "positions");
    l.normalAt = r.skipArray(mf & kHasNormals ? v : 0, 12, "normals");
    r.align(kAlign, "normals");
    l.texcoordAt = r.skipArray(mf & kHasTexcoords ? v : 0, 8, "texcoords");
    r.align(kAlign, "texcoords");
    l.indexAt = r.skipArray(n, mf & kIndex16 ? 2 : 4, "indices");
    r.align(kAlign, "indices");
    if (version < 3) continue;
    l.clusterHeaderAt = r.pos();
    l.clusters = r.u32("a cluster count");
    for (int k = 0; k < 3; ++k)
      if (r.u32("a cluster count") != 0) r.failAt(l.clusterHeaderAt + 4, which + ": reserved cluster field is not 0");
    if (l.clusters > n / 3 || uint64_t(l.clusters) * 40 > r.remaining())
      r.failAt(l.clusterHeaderAt, which + ": cluster count " + std::to_string(l.clusters) + " does not fit its " +
                                      std::to_string(n / 3) + " triangles or the file");
    l.clusterAt = r.skipArray(l.clusters, 40, "clusters");
    r.align(kAlign, "clusters");
    m.clusters.resize(l.clusters);
  }
  if (r.remaining() != 0) r.fail(std::to_string(r.remaining()) + " bytes after the last mesh");
  readArrays(bytes, scene, layout, threads, r);
  return scene;
}

Scene loadRtrScene(const std::filesystem::path& file) {
  const MappedFile mapped(file);
  Scene s = decodeRtrScene(mapped.bytes(), file.string());
  s.baseDir = file.parent_path();
  return s;
}

}  // namespace rtr
