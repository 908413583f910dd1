#include "scene/course.hpp"

#include <array>
#include <cmath>

#include "core/bounds.hpp"
#include "scene/binio.hpp"
#include "scene/lights.hpp"

namespace rtr {
namespace {

constexpr char kMagic[16] = {0, 0, 'C', 'O', 'M', 'P', '5', '8', '9', '2', 'M', 'm', 'e', 's', 'h', 0};
constexpr char kVariant[16] = {'d', 'e', 'f', 'a', 'u', 'l', 't', '-', 'a', '1', '2', 0, 0, 0, 0, 0};
constexpr uint32_t kMaxString = 32768;

void writeString(ByteWriter& w, const std::string& s) {
  if (s.size() + 1 >= kMaxString) throw Error("string longer than the course format allows: " + s.substr(0, 64));
  w.u32(uint32_t(s.size() + 1));
  w.bytes(s.data(), s.size());
  w.u8(0);
}

}  // namespace

bool isFallbackTexture(const std::filesystem::path& path) {
  const std::string n = path.filename().string();
  return n == kFallbackBaseColor || n == kFallbackOne || n == kFallbackEmissive;
}

std::string encodeCourseMesh(const Scene& scene) {
  ByteWriter w;
  w.bytes(kMagic, 16);
  w.bytes(kVariant, 16);
  w.u32(uint32_t(scene.textures.size()));
  for (const Texture& t : scene.textures) {
    writeString(w, t.path.generic_string());
    w.u8(t.srgb ? 1 : 0);
    w.u8(t.channels);
  }
  w.u32(uint32_t(scene.materials.size()));
  for (const Material& m : scene.materials)
    for (uint32_t s = 0; s < kCourseSlotCount; ++s) w.u32(m.textures[s]);
  w.u32(uint32_t(scene.meshes.size()));
  for (const Mesh& m : scene.meshes) {
    const size_t v = m.positions.size();
    if (m.normals.size() != v || (!m.texcoords.empty() && m.texcoords.size() != v))
      throw Error("mesh '" + m.name + "': attribute counts differ");
    w.u32(m.material);
    w.u32(uint32_t(v));
    w.u32(uint32_t(m.indices.size()));
    w.array(m.positions);
    w.array(m.normals);
    if (m.texcoords.empty()) w.data().append(v * 8, '\0');
    else w.array(m.texcoords);
    w.array(m.indices);
  }
  return std::move(w.data());
}

Scene decodeCourseMesh(std::span<const uint8_t> bytes, const std::string& file) {
  ByteReader r(bytes, file);
  char head[16];
  r.raw(head, 16, "the magic");
  if (std::memcmp(head, kMagic, 16) != 0) r.failAt(0, "not a .comp5892mesh file (magic mismatch)");
  r.raw(head, 16, "the variant");
  if (std::memcmp(head, kVariant, 16) != 0) r.failAt(16, "unsupported variant (expected 'default-a12')");

  Scene raw;
  const uint32_t texCount = r.count("texture count", 4 + 1 + 2);
  raw.textures.resize(texCount);
  for (Texture& t : raw.textures) {
    const size_t at = r.pos();
    const uint32_t n = r.u32("a texture path length");
    if (n == 0 || n >= kMaxString) r.failAt(at, "texture path length " + std::to_string(n) + " not in 1..32767");
    std::string_view s = r.view(n, "a texture path");
    if (s.back() != '\0') r.failAt(at + 4 + n - 1, "texture path not NUL-terminated");
    s.remove_suffix(1);
    if (s.find('\0') != std::string_view::npos) r.failAt(at + 4, "texture path contains NUL");
    t.path = std::filesystem::path(std::string(s));
    const size_t csAt = r.pos();
    const uint8_t cs = r.u8("a texture colour space");
    if (cs > 1) r.failAt(csAt, "texture colour space " + std::to_string(cs) + " is neither 0 (unorm) nor 1 (sRGB)");
    t.srgb = cs == 1;
    const uint8_t ch = r.u8("a texture channel count");
    if (ch < 1 || ch > 4) r.failAt(csAt + 1, "texture channel count " + std::to_string(ch) + " not in 1..4");
    t.channels = ch;
  }

  const uint32_t matCount = r.count("material count", 24);
  raw.materials.resize(matCount);
  for (uint32_t i = 0; i < matCount; ++i) {
    Material& m = raw.materials[i];
    m.name = "material" + std::to_string(i);
    for (uint32_t s = 0; s < kCourseSlotCount; ++s) {
      const size_t at = r.pos();
      const uint32_t id = r.u32("a material texture index");
      if (id != kNoTexture && id >= texCount)
        r.failAt(at, "texture index " + std::to_string(id) + " out of range (" + std::to_string(texCount) + " textures)");
      m.textures[s] = id;
    }
    if (m.textures[uint32_t(TextureSlot::AlphaMask)] != kNoTexture) m.flags |= kMaterialAlphaMasked;
  }

  const uint32_t meshCount = r.count("mesh count", 12);
  raw.meshes.resize(meshCount);
  for (uint32_t i = 0; i < meshCount; ++i) {
    Mesh& m = raw.meshes[i];
    m.name = "mesh" + std::to_string(i);
    size_t at = r.pos();
    m.material = r.u32("a mesh material index");
    if (m.material >= matCount)
      r.failAt(at, "mesh " + std::to_string(i) + ": material index " + std::to_string(m.material) + " out of range");
    const uint32_t v = r.u32("a vertex count");
    at = r.pos();
    const uint32_t n = r.u32("an index count");
    if (n % 3 != 0) r.failAt(at, "mesh " + std::to_string(i) + ": index count " + std::to_string(n) + " is not a multiple of 3");
    if ((uint64_t(v) * 32 + uint64_t(n) * 4) > r.remaining())
      r.failAt(at - 4, "mesh " + std::to_string(i) + ": " + std::to_string(v) + " vertices and " + std::to_string(n) +
                           " indices cannot fit in the " + std::to_string(r.remaining()) + " bytes left");
    const size_t posAt = r.pos();
    r.array(m.positions, v, "positions");
    r.array(m.normals, v, "normals");
    r.array(m.texcoords, v, "texcoords");
    const size_t idxAt = r.pos();
    r.array(m.indices, n, "indices");
    for (uint32_t k = 0; k < v; ++k) {
      const glm::vec3 p = m.positions[k], nn = m.normals[k];
      const glm::vec2 t = m.texcoords[k];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        r.failAt(posAt + size_t(k) * 12, "mesh " + std::to_string(i) + ": position " + std::to_string(k) + " is not finite");
      if (!coordinateOk(p))
        r.failAt(posAt + size_t(k) * 12, "mesh " + std::to_string(i) + ": position " + std::to_string(k) +
                                             " is beyond ±1e12 (the coordinate limit, docs/files-and-cli.md)");
      if (!std::isfinite(nn.x + nn.y + nn.z) || !std::isfinite(t.x + t.y))
        r.failAt(posAt + size_t(v) * 12 + size_t(k) * 12,
                 "mesh " + std::to_string(i) + ": vertex " + std::to_string(k) + " has a non-finite normal or texcoord");
      m.bounds.extend(p);
    }
    // The format always stores texcoords; all zeros means the source had none.
    bool anyTex = false;
    for (const glm::vec2& t : m.texcoords) anyTex |= t.x != 0.0f || t.y != 0.0f;
    if (!anyTex) m.texcoords.clear();
    for (uint32_t k = 0; k < n; ++k)
      if (m.indices[k] >= v)
        r.failAt(idxAt + size_t(k) * 4, "mesh " + std::to_string(i) + ": index " + std::to_string(m.indices[k]) +
                                            " out of range (" + std::to_string(v) + " vertices)");
  }
  if (r.remaining() != 0) r.fail(std::to_string(r.remaining()) + " bytes after the last mesh");

  // Fallback textures are an artefact of the format: drop them so materials say "no texture".
  Scene scene;
  std::vector<uint32_t> remap(texCount, kNoTexture);
  for (uint32_t t = 0; t < texCount; ++t) {
    if (isFallbackTexture(raw.textures[t].path)) continue;
    remap[t] = uint32_t(scene.textures.size());
    scene.textures.push_back(raw.textures[t]);
  }
  // The format has no scalar factors: its textures (fallbacks included) are the values. A fallback of
  // value one becomes factor 1 with no texture; the black emissive fallback becomes factor 0.
  for (Material& m : raw.materials) {
    const uint32_t emissive = m.texture(TextureSlot::Emissive);
    const bool emits = emissive != kNoTexture && !isFallbackTexture(raw.textures.at(emissive).path);
    m.baseColor = glm::vec3(1.0f);
    m.roughness = 1.0f;
    m.metalness = 1.0f;
    m.emissive = glm::vec3(emits ? 1.0f : 0.0f);
    for (uint32_t& id : m.textures) id = id == kNoTexture ? kNoTexture : remap[id];
  }
  scene.materials = std::move(raw.materials);
  scene.meshes = std::move(raw.meshes);
  // The format stores no lights; the course's Vulkan viewer lights every such scene with its standard light.
  scene.lights = {briefLight()};
  return scene;
}

Scene loadCourseMesh(const std::filesystem::path& file) {
  const MappedFile mapped(file);  // the header is checked before the rest is read
  Scene s = decodeCourseMesh(mapped.bytes(), file.string());
  s.baseDir = file.parent_path();
  return s;
}

}  // namespace rtr
