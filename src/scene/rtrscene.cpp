#include "scene/rtrscene.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <mutex>
#include <optional>
#include <exception>
#include <vector>

#include <glm/geometric.hpp>

#include "cluster.h"
#include "core/bounds.hpp"
#include "core/error.hpp"
#include "scene/binio.hpp"
#include "scene/rtrscene_arrays.hpp"
#include "scene/rtrscene_lod.hpp"
#include "core/parallel.hpp"
#include "scene/baked_texels.hpp"
#include "scene/rtrscene_texs.hpp"

namespace rtr {
using namespace rtrscene;
namespace {

constexpr char kMagic[8] = {'R', 'T', 'R', 'S', 'C', 'E', 'N', 'E'};
constexpr size_t kHeaderSize = 80;
constexpr size_t kAlign = 16;
constexpr size_t kGateTriangles = size_t(1) << 16;  // the indices a writer beside the clusters' build takes at once
constexpr uint32_t kMaxString = 32768;

constexpr uint32_t kHasView = 1u << 0;       // header flags
constexpr uint32_t kLightFalloff = 1u << 0;  // light flags
constexpr uint32_t kKnownMaterialFlags4 = kMaterialAlphaMasked | kMaterialDoubleSided | kMaterialLight;
constexpr uint32_t kKnownMaterialFlags = kKnownMaterialFlags4 | kMaterialBlend | kMaterialUnlit | kMaterialGltf;
constexpr uint32_t kNearestMag = 1u << 0, kNearestMin = 1u << 1, kNearestMip = 1u << 2;  // texture filter bits
// Minimum record sizes (a string is at least its length word), checked against the file before allocating.
constexpr size_t kLightSize4 = 80, kLightSize5 = 104, kInstanceSize = 80;
constexpr size_t kMaterialMin4 = 128, kMaterialMin5 = 4 + 4 + 28 * 4 + 7 * 4 + 7 * 24;

void writeString(ByteWriter& w, const std::string& s) {
  if (s.size() >= kMaxString) throw Error("string longer than 32767 bytes: " + s.substr(0, 64));
  w.u32(uint32_t(s.size()));
  w.bytes(s.data(), s.size());
  w.pad(4);
}

void writeVec(ByteWriter& w, const glm::vec3& v) {
  w.f32(v.x);
  w.f32(v.y);
  w.f32(v.z);
}

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

// What a scene holds that versions 1-4 cannot store (empty: nothing); writing it to one is refused, not dropped.
std::string newerThan4(const Scene& s) {
  if (!s.instances.empty()) return "instances";
  if (s.defaultFovYDeg != 0.0f) return "a field of view";
  for (const Light& l : s.lights)
    if (l.kind > Light::Kind::Headlight || l.range != 0.0f) return "spot or directional lights or light ranges";
  for (const Texture& t : s.textures)
    if (t.sourceChannel != 0 || !(t.sampler == SamplerDesc{})) return "texture samplers or source channels";
  for (const Material& m : s.materials) {
    if ((m.flags & ~kKnownMaterialFlags4) || m.opacity != 1.0f || m.alphaCutoff != 0.5f || m.normalScale != 1.0f ||
        m.occlusionStrength != 1.0f || m.texture(TextureSlot::Occlusion) != kNoTexture)
      return "glTF material fields";
    for (const UvTransform& u : m.uv)
      if (!u.identity() || u.texCoord != 0) return "uv transforms";
  }
  for (const Mesh& m : s.meshes)
    if (!m.texcoords1.empty() || !m.tangents.empty() || !m.colors.empty()) return "a second uv set, tangents or vertex colours";
  return {};
}

// A light the renderers cannot use (the caller has checked that its numbers are finite); null: none.
const char* lightFault(const Light& l) {
  if (l.range < 0.0f) return "negative range";
  if (l.innerConeCos < -1.0f || l.innerConeCos > 1.0f || l.outerConeCos < -1.0f || l.outerConeCos > 1.0f)
    return "cone cosine outside -1..1";
  if (l.kind == Light::Kind::Spot && l.outerConeCos > l.innerConeCos) return "outer cone narrower than the inner one";
  if ((l.kind == Light::Kind::Spot || l.kind == Light::Kind::Directional) && std::abs(glm::length(l.direction) - 1.0f) > 1e-3f)
    return "direction is not a unit vector";
  return nullptr;
}

// Version 6: chunks to the end of the payload. An unknown or repeated tag is refused, named with its offset.
// Version 6's chunks after the meshes: TEXS is read here; CLOD refers to the meshes' arrays, so only its
// place is returned, for reading once they are.
struct ChunkSpan {
  size_t at = 0, body = 0;
  uint64_t size = 0;
};
std::optional<ChunkSpan> readChunks(ByteReader& r, std::span<const uint8_t> bytes, Scene& scene,
                                    const std::shared_ptr<const void>& owner, const std::string& file) {
  std::optional<size_t> texs;
  std::optional<ChunkSpan> clod;
  while (r.remaining() != 0) {
    const size_t at = r.pos();
    char tag[4];
    r.raw(tag, 4, "a chunk header");
    std::string name(tag, 4);
    for (char& c : name) c = c >= 0x20 && c < 0x7F ? c : '?';
    if (r.u32("a chunk header") != 0) r.failAt(at + 4, "chunk '" + name + "': reserved field is not 0");
    const uint64_t size = r.pod<uint64_t>("a chunk header");
    if (size > r.remaining())
      r.failAt(at + 8, "chunk '" + name + "' of " + std::to_string(size) + " bytes: the file ends after " +
                           std::to_string(r.remaining()));
    if (name != "TEXS" && name != "CLOD") r.failAt(at, "unknown chunk '" + name + "'");
    const std::optional<size_t> first = name == "TEXS" ? texs : clod ? std::optional<size_t>(clod->at) : std::nullopt;
    if (first) r.failAt(at, "chunk '" + name + "' repeated (first at byte " + std::to_string(*first) + ")");
    if (name == "TEXS") {
      texs = at;
      readTexs(r, r.pos() + size, bytes, scene, owner, file);
    } else {
      clod = ChunkSpan{at, r.pos(), size};
      r.skip(size, "a chunk");
    }
    r.align(kAlign, "a chunk's padding");
  }
  return clod;
}

// At least the bytes encodeRtrScene writes (records and padding generously counted), so that its buffer is
// allocated once: a 4 GB scene grown by doubling copied itself about once more and held two buffers at
// the last step.
size_t sizeBound(const Scene& scene) {
  size_t n = 4096 + scene.lights.size() * 128 + scene.instances.size() * 80;
  for (const Texture& t : scene.textures) {
    n += 64 + t.path.native().size();
    if (t.baked) n += 64 + t.baked->pieces.size() * 16 + t.baked->data.size();
  }
  for (const Material& m : scene.materials) n += 1024 + m.name.size();
  for (const Mesh& m : scene.meshes) {
    auto bytes = [](const auto& a) { return a.size() * sizeof(a[0]); };
    n += 512 + m.name.size() + bytes(m.positions) + bytes(m.normals) + bytes(m.texcoords) + bytes(m.texcoords1) +
         bytes(m.tangents) + bytes(m.colors) + bytes(m.indices) + m.clusters.size() * 40;
    n += 64 + m.lod.clusters.size() * 96 + m.lod.indices.size() * 4;
  }
  return n;
}

// The whole file into `w` (in memory, or streaming to a file), its header's size and checksum patched last.
void encode(ByteWriter& w, const Scene& scene, uint32_t version, unsigned threads, const WriteGate& ready = {}) {
  if (version < 1 || version > kRtrSceneVersion || (version < 2 && !scene.lights.empty()))
    throw Error("cannot encode .rtrscene version " + std::to_string(version) + (scene.lights.empty() ? "" : " with lights"));
  if (const std::string what = newerThan4(scene); version < 5 && !what.empty())
    throw Error("cannot encode .rtrscene version " + std::to_string(version) + " with " + what);
  if (version < 6 && hasBakedTextures(scene))
    throw Error("cannot encode .rtrscene version " + std::to_string(version) + " with baked textures");
  for (const Light& l : scene.lights)
    if (const char* f = lightFault(l)) throw Error(std::string("cannot encode a light: ") + f);
  for (const Instance& i : scene.instances)
    if (i.mesh >= scene.meshes.size())
      throw Error("cannot encode an instance of mesh " + std::to_string(i.mesh) + ": no such mesh");
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
  if (version >= 5) {
    w.u32(uint32_t(scene.instances.size()));
    w.f32(scene.defaultFovYDeg);
  }
  w.pad(kAlign);

  for (const Light& l : scene.lights) {  // 80 bytes each, 104 from version 5
    w.u32(uint32_t(l.kind));
    w.u32(l.falloff ? kLightFalloff : 0);
    for (const glm::vec3& v : {l.position, l.color, l.corner, l.edge1, l.edge2, l.normal}) writeVec(w, v);
    if (version < 5) continue;
    writeVec(w, l.direction);
    w.f32(l.innerConeCos);
    w.f32(l.outerConeCos);
    w.f32(l.range);
  }
  if (version >= 5) w.pad(kAlign);
  for (const Instance& i : scene.instances) {  // version 5: 80 bytes each (none before: refused above)
    w.u32(i.mesh);
    w.zeros(12);
    w.pod(i.transform);  // column-major, as glm holds it
  }
  for (const Texture& t : scene.textures) {
    if (t.bytes) throw Error("texture '" + t.path.string() + "' is held in memory: write it to a file first (rtr-bake does)");
    w.u8(t.srgb ? 1 : 0);
    w.u8(t.channels);
    if (version >= 5) {
      w.u8(t.sourceChannel);
      w.u8(uint8_t(t.sampler.wrapU));
      w.u8(uint8_t(t.sampler.wrapV));
      w.u8((t.sampler.nearestMag ? kNearestMag : 0) | (t.sampler.nearestMin ? kNearestMin : 0) |
           (t.sampler.nearestMip ? kNearestMip : 0));
    }
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
    if (version < 5) {
      for (uint32_t s = 0; s < kCourseSlotCount; ++s) w.u32(m.textures[s]);
      continue;
    }
    for (float f : {m.opacity, m.alphaCutoff, m.normalScale, m.occlusionStrength}) w.f32(f);
    for (uint32_t id : m.textures) w.u32(id);
    for (const UvTransform& u : m.uv) {
      for (float f : {u.offset.x, u.offset.y, u.rotation, u.scale.x, u.scale.y}) w.f32(f);
      w.u32(u.texCoord);
    }
  }
  w.pad(kAlign);
  for (const Mesh& m : scene.meshes) {
    const size_t v = m.positions.size();
    auto sized = [v](const auto& a) { return a.empty() || a.size() == v; };
    if (!sized(m.normals) || !sized(m.texcoords) || !sized(m.texcoords1) || !sized(m.tangents) || !sized(m.colors))
      throw Error("mesh '" + m.name + "': attribute counts differ");
    const bool small = v <= 0x10000;
    const uint32_t present[kVertexStreams] = {
        1, !m.normals.empty(), !m.texcoords.empty(), !m.texcoords1.empty(), !m.tangents.empty(), !m.colors.empty()};
    uint32_t flags = small ? kIndex16 : 0;
    for (size_t s = 1; s < kVertexStreams; ++s) flags |= present[s] ? kStreamFlag[s] : 0;
    w.u32(m.material);
    w.u32(flags);
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
    if (version >= 5) {  // empty before (refused above)
      w.array(m.texcoords1);
      w.pad(kAlign);
      w.array(m.tangents);
      w.pad(kAlign);
      w.array(m.colors);
      w.pad(kAlign);
    }
    // The indices in blocks of whole triangles, each once it is final (ready: the clusters may still be
    // reordering the ones after it).
    const size_t mesh = size_t(&m - scene.meshes.data()), triangles = m.indices.size() / 3;
    for (size_t f = 0; f < m.indices.size(); f += kGateTriangles * 3) {
      const size_t e = std::min(m.indices.size(), f + kGateTriangles * 3);
      if (ready) ready(mesh, e / 3);
      if (!small) {
        w.bytes(m.indices.data() + f, (e - f) * 4);
        continue;
      }
      uint16_t part[4096];
      for (size_t k = f; k < e; k += std::size(part)) {
        const size_t n = std::min(std::size(part), e - k);
        std::copy_n(m.indices.begin() + ptrdiff_t(k), n, part);
        w.bytes(part, n * 2);
      }
    }
    w.pad(kAlign);
    // Version 3: the clusters (zero: none stored, built at load).
    if (version < 3) continue;
    if (ready) ready(mesh, triangles);
    w.u32(uint32_t(m.clusters.size()));
    w.zeros(12);
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
  // Version 6: chunks, each a 16-byte header {tag, 0, u64 body size}, the body, pad16.
  const auto chunk = [&w](const char* tag, const auto& writeBody) {
    w.bytes(tag, 4);
    w.u32(0);
    const size_t sizeAt = w.hole(8);
    writeBody();
    const uint64_t body = w.size() - sizeAt - 8;
    w.patch(sizeAt, &body, 8);
    w.pad(kAlign);
  };
  if (ready) ready(scene.meshes.size(), 0);
  if (hasBakedTextures(scene)) chunk("TEXS", [&] { writeTexs(w, scene); });
  if (version >= 6 && hasClusterLods(scene)) chunk("CLOD", [&] { writeClusterLods(w, scene); });
  const uint64_t payload = w.size() - kHeaderSize;
  uint64_t sum;
  if (version >= 4) {
    sum = w.finishPayload(kHeaderSize, threads);
  } else {  // one chain: in memory only (older versions are written for the reader's tests)
    const auto* b = reinterpret_cast<const uint8_t*>(w.data().data());
    sum = checksum64({b + kHeaderSize, payload});
  }
  w.patch(32, &payload, 8);
  w.patch(40, &sum, 8);
}

}  // namespace

std::string encodeRtrScene(const Scene& scene, uint32_t version) {
  ByteWriter w;
  w.reserve(sizeBound(scene));
  encode(w, scene, version, 0);
  return std::move(w.data());
}

uint64_t writeRtrScene(const Scene& scene, AtomicFile& file, unsigned threads, size_t window, const WriteGate& ready) {
  ByteWriter w(file.fd(), file.target().string(), kHeaderSize, threads, window);
  encode(w, scene, kRtrSceneVersion, threads, ready);
  return w.size();
}

Scene decodeRtrScene(std::span<const uint8_t> bytes, const std::string& file, unsigned threads,
                     const std::shared_ptr<const void>& owner) {
  if (!bytes.empty() && reinterpret_cast<uintptr_t>(bytes.data()) % alignof(uint32_t) != 0) {  // arrays read in place
    std::vector<uint32_t> aligned((bytes.size() + 3) / 4);
    std::memcpy(aligned.data(), bytes.data(), bytes.size());
    return decodeRtrScene({reinterpret_cast<const uint8_t*>(aligned.data()), bytes.size()}, file, threads, nullptr);
  }
  if (threads == 0 && bytes.size() < (size_t(4) << 20)) threads = 1;  // a small file: starting threads costs more
  ByteReader r(bytes, file);
  char magic[8];
  r.raw(magic, 8, "the header");
  if (std::memcmp(magic, kMagic, 8) != 0) r.failAt(0, "not an .rtrscene file (magic mismatch)");
  const uint32_t version = r.u32("the header");
  if (version < 1 || version > kRtrSceneVersion)
    r.failAt(8,
             "unsupported version " + std::to_string(version) + " (this build reads " + std::to_string(kRtrSceneVersion) + ")");
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
  uint32_t instanceCount = 0;
  if (version >= 5) {
    instanceCount = r.u32("the header");
    scene.defaultFovYDeg = readFinite(r, "the field of view");
    if (scene.defaultFovYDeg < 0.0f || scene.defaultFovYDeg >= 180.0f)
      r.failAt(72, "field of view " + std::to_string(scene.defaultFovYDeg) + " not in 0..180 degrees");
    if (r.u32("the header") != 0) r.failAt(76, "reserved field is not 0");
  }
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
  const bool v5 = version >= 5;
  if (uint64_t(lightCount) * (v5 ? kLightSize5 : kLightSize4) > r.remaining())
    r.failAt(28, "light count " + std::to_string(lightCount) + " cannot fit in the file");
  if (uint64_t(instanceCount) * kInstanceSize > r.remaining())
    r.failAt(68, "instance count " + std::to_string(instanceCount) + " cannot fit in the file");
  if (uint64_t(texCount) * (v5 ? 12 : 8) > r.remaining())
    r.failAt(16, "texture count " + std::to_string(texCount) + " cannot fit in the file");
  if (uint64_t(matCount) * (v5 ? kMaterialMin5 : kMaterialMin4) > r.remaining())
    r.failAt(20, "material count " + std::to_string(matCount) + " cannot fit in the file");
  if (uint64_t(meshCount) * 64 > r.remaining())
    r.failAt(24, "mesh count " + std::to_string(meshCount) + " cannot fit in the file");

  scene.lights.resize(lightCount);
  for (Light& l : scene.lights) {
    const size_t at = r.pos();
    const uint32_t kind = r.u32("a light record"), lflags = r.u32("a light record");
    if (kind > uint32_t(v5 ? Light::Kind::Directional : Light::Kind::Headlight))
      r.failAt(at, "unknown light kind " + std::to_string(kind));
    if (lflags & ~kLightFalloff) r.failAt(at + 4, "unknown light flags");
    l.kind = Light::Kind(kind);
    l.falloff = (lflags & kLightFalloff) != 0;
    for (glm::vec3* v : {&l.position, &l.color, &l.corner, &l.edge1, &l.edge2, &l.normal}) *v = readVec(r, "a light");
    if (!v5) continue;
    l.direction = readVec(r, "a light");
    l.innerConeCos = readFinite(r, "a light");
    l.outerConeCos = readFinite(r, "a light");
    l.range = readFinite(r, "a light");
    if (const char* f = lightFault(l)) r.failAt(at, std::string("light: ") + f);
  }
  if (v5) r.align(kAlign, "the light table");

  scene.instances.resize(instanceCount);
  for (Instance& inst : scene.instances) {
    const size_t at = r.pos();
    inst.mesh = r.u32("an instance record");
    if (inst.mesh >= meshCount)
      r.failAt(at, "instance of mesh " + std::to_string(inst.mesh) + ": out of range (" + std::to_string(meshCount) + " meshes)");
    for (int k = 0; k < 3; ++k)
      if (r.u32("an instance record") != 0) r.failAt(at + 4, "reserved instance field is not 0");
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 4; ++k) inst.transform[c][k] = readFinite(r, "an instance transform");
  }

  scene.textures.resize(texCount);
  for (Texture& t : scene.textures) {
    const size_t at = r.pos();
    const uint8_t srgb = r.u8("a texture record"), ch = r.u8("a texture record");
    if (srgb > 1) r.failAt(at, "texture sRGB flag " + std::to_string(srgb) + " is neither 0 nor 1");
    if (ch < 1 || ch > 4) r.failAt(at + 1, "texture channel count " + std::to_string(ch) + " not in 1..4");
    t.srgb = srgb == 1;
    t.channels = ch;
    if (v5) {
      t.sourceChannel = r.u8("a texture record");
      const uint8_t wrapU = r.u8("a texture record"), wrapV = r.u8("a texture record"), filter = r.u8("a texture record");
      if (t.sourceChannel > (ch == 1 ? 4 : 0))
        r.failAt(at + 2,
                 "texture source channel " + std::to_string(t.sourceChannel) + " for " + std::to_string(ch) + " channels");
      for (uint8_t wrap : {wrapU, wrapV})
        if (wrap > uint8_t(Wrap::MirroredRepeat)) r.failAt(at + 3, "unknown texture wrap mode " + std::to_string(wrap));
      if (filter & ~(kNearestMag | kNearestMin | kNearestMip)) r.failAt(at + 5, "unknown texture filter flags");
      t.sampler = {Wrap(wrapU), Wrap(wrapV), (filter & kNearestMag) != 0, (filter & kNearestMin) != 0,
                   (filter & kNearestMip) != 0};
    }
    const size_t reservedAt = r.pos();
    if (r.pod<uint16_t>("a texture record") != 0 && v5) r.failAt(reservedAt, "reserved texture field is not 0");
    t.path = readString(r, "a texture path");
    if (t.path.empty()) r.failAt(reservedAt + 2, "empty texture path");
  }
  r.align(kAlign, "the texture table");

  scene.materials.resize(matCount);
  for (Material& m : scene.materials) {
    const size_t at = r.pos();
    m.flags = r.u32("a material record");
    if (m.flags & ~(v5 ? kKnownMaterialFlags : kKnownMaterialFlags4)) r.failAt(at, "unknown material flags");
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
    if (v5)
      for (float* f : {&m.opacity, &m.alphaCutoff, &m.normalScale, &m.occlusionStrength}) *f = readFinite(r, "a material factor");
    for (uint32_t s = 0; s < (v5 ? kTextureSlotCount : kCourseSlotCount); ++s) {
      uint32_t& id = m.textures[s];
      const size_t idAt = r.pos();
      id = r.u32("a material texture index");
      if (id != kNoTexture && id >= texCount)
        r.failAt(idAt, "texture index " + std::to_string(id) + " out of range (" + std::to_string(texCount) + " textures)");
    }
    if (!v5) continue;
    for (UvTransform& u : m.uv) {
      for (float* f : {&u.offset.x, &u.offset.y, &u.rotation, &u.scale.x, &u.scale.y}) *f = readFinite(r, "a uv transform");
      const size_t setAt = r.pos();
      u.texCoord = r.u32("a uv transform");
      if (u.texCoord > 1) r.failAt(setAt, "uv set " + std::to_string(u.texCoord) + " is neither 0 nor 1");
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
    const uint32_t known = kHasNormals | kHasTexcoords | kIndex16 | (v5 ? kHasTexcoords1 | kHasTangents | kHasColors : 0);
    if (mf & ~known) r.failAt(at + 4, which + ": unknown mesh flags");
    const uint32_t v = r.u32("a mesh record"), n = r.u32("a mesh record");
    if (n % 3 != 0) r.failAt(at + 12, which + ": index count " + std::to_string(n) + " is not a multiple of 3");
    if ((mf & kIndex16) && v > 0x10000) r.failAt(at + 4, which + ": 16-bit indices with more than 65536 vertices");
    l.flags = mf;
    l.vertices = v;
    l.indices = n;
    uint64_t need = uint64_t(n) * l.elementSize(kIndices);
    for (uint8_t s = kPositions; s < kVertexStreams; ++s) need += uint64_t(l.count(Stream(s))) * kVertexSize[s];
    if (need > r.remaining())
      r.failAt(at + 8, which + ": " + std::to_string(v) + " vertices and " + std::to_string(n) + " indices cannot fit in the " +
                           std::to_string(r.remaining()) + " bytes left");
    m.bounds.min = readVec(r, "mesh bounds");
    m.bounds.max = readVec(r, "mesh bounds");
    if (v > 0 && !(coordinateOk(m.bounds.min) && coordinateOk(m.bounds.max)))  // positions lie inside them
      r.failAt(at + 16, which + ": bounds beyond ±1e12 (the coordinate limit, docs/files-and-cli.md)");
    if (v == 0) m.bounds = Bounds{};
    m.name = readString(r, "a mesh name");
    r.align(kAlign, "a mesh record");
    for (uint8_t s = kPositions; s < kVertexStreams; ++s) {
      l.at[s] = r.skipArray(l.count(Stream(s)), kVertexSize[s], kStreamName[s]);
      r.align(kAlign, kStreamName[s]);
    }
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
    placeClusters(m, l, bytes.data(), owner);
  }
  if (version < 6 && r.remaining() != 0) r.fail(std::to_string(r.remaining()) + " bytes after the last mesh");
  const std::optional<ChunkSpan> clod = readChunks(r, bytes, scene, owner, file);
  // The hierarchies' mesh records are read first, their records and indices with the meshes' arrays. A
  // fault in those mesh records waits: the arrays, before the chunk, may hold one at a lower offset.
  std::vector<LodLayout> lods;
  std::exception_ptr lodFault;
  if (clod) {
    ByteReader body(bytes.first(clod->body + clod->size), file);
    body.skip(clod->body, "a chunk");
    try {
      readClusterLodLayout(body, clod->size, scene, lods);
    } catch (const Error&) { lodFault = std::current_exception(); }
  }
  readArrays(bytes, scene, layout, lods, threads, r, owner);
  if (lodFault) std::rethrow_exception(lodFault);
  return scene;
}

Scene loadRtrScene(const std::filesystem::path& file) {
  // Kept mapped while baked texels point into it (until the scene's last texture goes).
  const auto mapped = std::make_shared<const MappedFile>(file);
  Scene s = decodeRtrScene(mapped->bytes(), file.string(), 0, mapped);
  s.baseDir = file.parent_path();
  return s;
}

}  // namespace rtr
