#include "scene/rtrscene.hpp"

#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

#include "cluster.h"
#include "scene/binio.hpp"

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

// Clusters must tile the mesh's triangles in order, each within the GPU's limits, its sphere holding its
// vertices: the culling pass and the compute rasteriser trust them.
void readClusters(ByteReader& r, Mesh& m, const std::string& which) {
  const size_t at = r.pos();
  const uint32_t count = r.u32("a cluster count");
  for (int k = 0; k < 3; ++k)
    if (r.u32("a cluster count") != 0) r.failAt(at + 4, which + ": reserved cluster field is not 0");
  const uint32_t triangles = m.triangleCount();
  if (count > triangles || uint64_t(count) * 40 > r.remaining())
    r.failAt(at, which + ": cluster count " + std::to_string(count) + " does not fit its " + std::to_string(triangles) +
                     " triangles or the file");
  m.clusters.resize(count);
  uint32_t next = 0;
  std::vector<uint32_t> seenIn(count ? m.positions.size() : 0, ~0u);  // per vertex: the last cluster that used it
  for (uint32_t i = 0; i < count; ++i) {
    Cluster& c = m.clusters[i];
    const size_t cAt = r.pos();
    const std::string cw = which + ": cluster " + std::to_string(i);
    c.center = readVec(r, "a cluster's sphere");
    c.radius = readFinite(r, "a cluster's sphere");
    c.coneAxis = readVec(r, "a cluster's cone");
    c.coneCutoff = readFinite(r, "a cluster's cone");
    c.firstTriangle = r.u32("a cluster record");
    c.triangleCount = r.u32("a cluster record");
    if (!(c.radius >= 0.0f)) r.failAt(cAt + 12, cw + ": negative radius");
    // A cone that culls (cutoff < 1) has a unit axis and a cutoff >= 0 (meshoptimizer's); others would cull
    // clusters that face the eye.
    if (c.coneCutoff < 1.0f && (c.coneCutoff < 0.0f || std::abs(glm::length(c.coneAxis) - 1.0f) > 1e-3f))
      r.failAt(cAt + 16, cw + ": cone axis not a unit vector or cutoff below 0");
    if (c.firstTriangle != next)
      r.failAt(cAt + 32, cw + ": first triangle " + std::to_string(c.firstTriangle) + " is not " + std::to_string(next) +
                             " (clusters tile the triangles in order)");
    if (c.triangleCount < 1 || c.triangleCount > CLUSTER_MAX_TRIANGLES || c.triangleCount > triangles - next)
      r.failAt(cAt + 36, cw + ": triangle count " + std::to_string(c.triangleCount) + " not in 1.." +
                             std::to_string(std::min<uint32_t>(CLUSTER_MAX_TRIANGLES, triangles - next)));
    next += c.triangleCount;
    uint32_t distinct = 0;
    const float slack = c.radius * 1e-4f + 1e-6f * (std::abs(c.center.x) + std::abs(c.center.y) + std::abs(c.center.z));
    for (size_t k = size_t(c.firstTriangle) * 3; k < size_t(next) * 3; ++k) {
      const uint32_t v = m.indices[k];
      if (seenIn[v] == i) continue;  // each vertex checked once per cluster
      seenIn[v] = i;
      if (++distinct > CLUSTER_MAX_VERTICES)
        r.failAt(cAt, cw + ": more than " + std::to_string(CLUSTER_MAX_VERTICES) + " vertices");
      if (!(glm::length(m.positions[v] - c.center) <= c.radius + slack))
        r.failAt(cAt, cw + ": vertex " + std::to_string(v) + " lies outside its bounding sphere");
    }
  }
  if (count && next != triangles)
    r.failAt(at, which + ": clusters cover " + std::to_string(next) + " of " + std::to_string(triangles) + " triangles");
  r.align(kAlign, "clusters");
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
    for (uint32_t id : m.textures) w.u32(id);
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
  const uint64_t sum = checksum64({reinterpret_cast<const uint8_t*>(out.data()) + kHeaderSize, payload});
  std::memcpy(out.data() + 32, &payload, 8);
  std::memcpy(out.data() + 40, &sum, 8);
  return std::move(out);
}

Scene decodeRtrScene(std::span<const uint8_t> bytes, const std::string& file) {
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
  if (checksum64(bytes.subspan(kHeaderSize)) != sum) r.failAt(40, "checksum mismatch: the payload is corrupt");
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
    for (uint32_t& id : m.textures) {
      const size_t idAt = r.pos();
      id = r.u32("a material texture index");
      if (id != kNoTexture && id >= texCount)
        r.failAt(idAt, "texture index " + std::to_string(id) + " out of range (" + std::to_string(texCount) + " textures)");
    }
  }
  r.align(kAlign, "the material table");

  scene.meshes.resize(meshCount);
  for (uint32_t i = 0; i < meshCount; ++i) {
    Mesh& m = scene.meshes[i];
    const std::string which = "mesh " + std::to_string(i);
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
    const size_t posAt = r.pos();
    r.array(m.positions, v, "positions");
    r.align(kAlign, "positions");
    if (mf & kHasNormals) r.array(m.normals, v, "normals");
    r.align(kAlign, "normals");
    if (mf & kHasTexcoords) r.array(m.texcoords, v, "texcoords");
    r.align(kAlign, "texcoords");
    const size_t idxAt = r.pos();
    if (mf & kIndex16) {
      std::vector<uint16_t> small;
      r.array(small, n, "indices");
      m.indices.assign(small.begin(), small.end());
    } else {
      r.array(m.indices, n, "indices");
    }
    r.align(kAlign, "indices");
    for (uint32_t k = 0; k < v; ++k) {
      const glm::vec3 p = m.positions[k];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        r.failAt(posAt + size_t(k) * 12, which + ": position " + std::to_string(k) + " is not finite");
      if (!(p.x >= m.bounds.min.x && p.y >= m.bounds.min.y && p.z >= m.bounds.min.z && p.x <= m.bounds.max.x &&
            p.y <= m.bounds.max.y && p.z <= m.bounds.max.z))
        r.failAt(posAt + size_t(k) * 12, which + ": position " + std::to_string(k) + " lies outside the mesh bounds");
    }
    for (const glm::vec3& nn : m.normals)
      if (!std::isfinite(nn.x + nn.y + nn.z)) r.failAt(posAt, which + ": a normal is not finite");
    for (const glm::vec2& t : m.texcoords)
      if (!std::isfinite(t.x + t.y)) r.failAt(posAt, which + ": a texcoord is not finite");
    for (uint32_t k = 0; k < n; ++k)
      if (m.indices[k] >= v)
        r.failAt(idxAt + size_t(k) * (mf & kIndex16 ? 2 : 4),
                 which + ": index " + std::to_string(m.indices[k]) + " out of range (" + std::to_string(v) + " vertices)");
    if (version >= 3) readClusters(r, m, which);
  }
  if (r.remaining() != 0) r.fail(std::to_string(r.remaining()) + " bytes after the last mesh");
  return scene;
}

Scene loadRtrScene(const std::filesystem::path& file) {
  const MappedFile mapped(file);
  Scene s = decodeRtrScene(mapped.bytes(), file.string());
  s.baseDir = file.parent_path();
  return s;
}

}  // namespace rtr
