#include "scene/gltf.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <numeric>
#include <set>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <simdjson.h>

#include "core/error.hpp"
#include "core/parallel.hpp"
#include "scene/binio.hpp"
#include "scene/gltf_accessors.hpp"
#include "scene/gltf_compress.hpp"
#include "scene/gltf_json.hpp"
#include "scene/gltf_materials.hpp"
#include "scene/mesh_ops.hpp"

namespace rtr {

namespace {

using gltf::Json;

constexpr std::string_view kSupported[] = {
    "KHR_materials_emissive_strength", "KHR_texture_transform",      "KHR_lights_punctual", "KHR_mesh_quantization",
    "EXT_meshopt_compression",         "KHR_draco_mesh_compression", "KHR_materials_unlit"};

struct Glb {
  std::span<const uint8_t> json, bin;
};

uint32_t le32(std::span<const uint8_t> d, size_t at) {
  uint32_t v;
  std::memcpy(&v, d.data() + at, 4);
  return v;
}

// The GLB container: a 12-byte header, a JSON chunk, then optionally a BIN chunk (others are skipped).
Glb splitGlb(std::span<const uint8_t> d, const std::string& name) {
  auto fail = [&](size_t at, const std::string& what) { throw fileError(name, "byte " + std::to_string(at), what); };
  if (d.size() < 12) fail(0, "a GLB header needs 12 bytes, the file has " + std::to_string(d.size()));
  if (const uint32_t v = le32(d, 4); v != 2) fail(4, "GLB version " + std::to_string(v) + " (rtr reads version 2)");
  const uint32_t length = le32(d, 8);
  if (length > d.size())
    fail(8,
         "the GLB header's length " + std::to_string(length) + " is more than the file's " + std::to_string(d.size()) + " bytes");
  d = d.first(length);
  Glb g;
  for (size_t pos = 12, chunk = 0; pos < d.size(); ++chunk) {
    if (d.size() - pos < 8) fail(pos, "a chunk header needs 8 bytes, " + std::to_string(d.size() - pos) + " are left");
    const uint32_t len = le32(d, pos), type = le32(d, pos + 4);
    if (len > d.size() - pos - 8)
      fail(pos, "chunk " + std::to_string(chunk) + "'s length " + std::to_string(len) + " runs past the end of the GLB (" +
                    std::to_string(d.size() - pos - 8) + " bytes left)");
    const auto data = d.subspan(pos + 8, len);
    if (chunk == 0 && type != 0x4E4F534Au) fail(pos + 4, "the first chunk is not JSON");
    if (chunk == 0) g.json = data;
    else if (chunk == 1 && type == 0x004E4942u) g.bin = data;
    pos += 8 + size_t(len);
  }
  if (g.json.empty()) fail(12, "the GLB has no JSON chunk");
  return g;
}

glm::mat4 localMatrix(const Json& n) {
  if (n.get("matrix")) {
    float a[16];
    n.numbers("matrix", a);
    glm::mat4 m;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[c][r] = a[c * 4 + r];  // column-major, as glm
    return m;
  }
  float t[3] = {0, 0, 0}, r[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
  n.numbers("translation", t);
  n.numbers("rotation", r);
  n.numbers("scale", s);
  glm::quat q(r[3], r[0], r[1], r[2]);
  const float l = glm::length(q);
  q = l > 0 ? q / l : glm::quat(1, 0, 0, 0);
  return glm::translate(glm::mat4(1.0f), glm::vec3(t[0], t[1], t[2])) * glm::mat4_cast(q) *
         glm::scale(glm::mat4(1.0f), glm::vec3(s[0], s[1], s[2]));
}

bool finite(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

class Loader {
 public:
  Loader(const std::string& name, std::filesystem::path baseDir, const LoadOptions& options)
      : name_(name), baseDir_(std::move(baseDir)), opt_(options) {}

  Scene run(std::span<const uint8_t> bytes) {
    std::span<const uint8_t> json = bytes, bin;
    const bool glb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    if (glb) {
      const Glb g = splitGlb(bytes, name_);
      json = g.json;
      bin = g.bin;
    } else if (json.size() >= 3 && std::memcmp(json.data(), "\xEF\xBB\xBF", 3) == 0) {
      json = json.subspan(3);  // a UTF-8 byte order mark
    }
    simdjson::dom::parser parser;
    simdjson::dom::element doc;
    if (auto err = parser.parse(json.data(), json.size()).get(doc))
      throw fileError(name_, glb ? "JSON chunk" : "", std::string("not valid JSON: ") + simdjson::error_message(err));
    const Json root(doc, "", &name_);
    if (!root.isObject()) root.fail("a glTF file is a JSON object");
    const Json version = root.at("asset").at("version");
    if (version.string().substr(0, 2) != "2.")
      version.fail("glTF version '" + std::string(version.string()) + "' (rtr reads glTF 2.0)");
    checkExtensions(root);

    scene_.baseDir = baseDir_;
    gltf::Accessors acc(root, baseDir_, bin, glb);
    gltf::Materials mats(
        root, acc, scene_, [&](const std::string& s) { note(s); }, [&](const std::string& s) { warn(s); });
    acc_ = &acc;
    mats_ = &mats;
    traverse(root);
    readDeferred();
    if (root.count("animations") || root.count("skins")) animated_ = true;
    if (animated_) note("animations, skins and morph targets are not played: the meshes are shown at rest");
    if (skipped_)
      note(std::to_string(skipped_) + " primitive(s) of points or lines (or without POSITION) left out: rtr draws triangles");
    if (warnings_ > kShownWarnings)
      message(opt_.warn, "warning", std::to_string(warnings_) + " warnings, first " + std::to_string(kShownWarnings) + " shown");
    if (scene_.instances.empty())
      throw fileError(
          name_, "",
          "the scene has no triangles to draw" +
              (skipped_ ? " (" + std::to_string(skipped_) + " primitive(s) of points or lines left out)" : std::string()));
    return std::move(scene_);
  }

 private:
  void message(const std::function<void(const std::string&)>& f, const char* kind, const std::string& s) {
    const std::string line = name_ + ": " + s;
    if (!said_.insert(line).second) return;
    if (f) f(line);
    else std::cerr << kind << ": " << line << "\n";
  }
  void note(const std::string& s) { message(opt_.note, "note", s); }
  // At most kShownWarnings are passed on, then one line with the total (as the OBJ reader does).
  static constexpr size_t kShownWarnings = 10;
  void warn(const std::string& s) {
    if (++warnings_ <= kShownWarnings) message(opt_.warn, "warning", s);
  }

  void checkExtensions(const Json& root) {
    auto supported = [](std::string_view e) {
      return std::find(std::begin(kSupported), std::end(kSupported), e) != std::end(kSupported);
    };
    std::set<std::string_view> required;
    if (auto req = root.get("extensionsRequired"))
      for (size_t i = 0, n = req->size(); i < n; ++i) {
        const std::string_view e = (*req)[i].string();
        if (!supported(e)) (*req)[i].fail("the file requires extension '" + std::string(e) + "', which rtr does not support");
        required.insert(e);
      }
    std::string ignored;
    if (auto used = root.get("extensionsUsed"))
      for (size_t i = 0, n = used->size(); i < n; ++i) {
        const std::string_view e = (*used)[i].string();
        if (!supported(e)) ignored += (ignored.empty() ? "" : ", ") + std::string(e);
      }
    if (!ignored.empty()) note("extensions not supported, ignored (the file does not require them): " + ignored);
  }

  void traverse(const Json& root) {
    const size_t nodeCount = root.count("nodes");
    std::vector<uint32_t> roots;
    if (root.count("scenes")) {
      const Json scenes = root.at("scenes");
      const Json s = scenes[root.get("scene") ? root.index("scene", scenes.size(), "scenes") : 0];
      if (s.get("nodes")) {
        const Json list = s.at("nodes");
        for (size_t i = 0, n = list.size(); i < n; ++i) {
          const uint64_t v = list[i].uinteger();
          if (v >= nodeCount) list[i].fail(std::to_string(v) + " is not one of the " + std::to_string(nodeCount) + " nodes");
          roots.push_back(uint32_t(v));
        }
      }
    } else {  // no scenes: the nodes nobody names as a child are the roots
      std::vector<uint8_t> child(nodeCount, 0);
      for (size_t i = 0; i < nodeCount; ++i) {
        const Json n = root.at("nodes")[i];
        if (auto c = n.get("children"))
          for (size_t k = 0, m = c->size(); k < m; ++k) {
            const uint64_t v = (*c)[k].uinteger();
            if (v < nodeCount) child[v] = 1;
          }
      }
      for (size_t i = 0; i < nodeCount; ++i)
        if (!child[i]) roots.push_back(uint32_t(i));
    }
    std::vector<uint8_t> seen(nodeCount, 0);
    std::vector<std::pair<uint32_t, glm::mat4>> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, glm::mat4(1.0f)});
    const Json nodes = nodeCount ? root.at("nodes") : root;
    while (!stack.empty()) {
      const auto [ni, parent] = stack.back();
      stack.pop_back();
      const Json n = nodes[ni];
      if (seen[ni]) n.fail("the node is reached twice from the scene's roots (a cycle, or a node with two parents)");
      seen[ni] = 1;
      const glm::mat4 world = parent * localMatrix(n);
      if (!finite(world)) n.fail("the node's transform is not finite");
      if (n.get("skin") || n.get("weights")) animated_ = true;
      if (n.get("mesh")) {
        const uint32_t mi = n.index("mesh", root.count("meshes"), "meshes");
        for (uint32_t id : meshPrimitives(root, mi)) scene_.instances.push_back({id, world});
      }
      if (n.get("camera") && !cameraDone_) camera(root, n, world);
      if (auto ext = n.get("extensions"))
        if (auto l = ext->get("KHR_lights_punctual")) light(root, *l, world);
      if (auto c = n.get("children"))
        for (size_t k = c->size(); k-- > 0;) {
          const uint64_t v = (*c)[k].uinteger();
          if (v >= nodeCount) (*c)[k].fail(std::to_string(v) + " is not one of the " + std::to_string(nodeCount) + " nodes");
          stack.push_back({uint32_t(v), world});
        }
    }
  }

  const std::vector<uint32_t>& meshPrimitives(const Json& root, uint32_t mi) {
    if (meshes_.empty()) meshes_.resize(root.count("meshes"));
    if (meshes_[mi]) return *meshes_[mi];
    const Json mesh = root.at("meshes")[mi];
    const Json prims = mesh.at("primitives");
    const size_t n = prims.size();
    std::vector<uint32_t> ids;
    const std::string base = mesh.get("name") ? std::string(mesh.string("name", "")) : "mesh " + std::to_string(mi);
    for (size_t p = 0; p < n; ++p)
      if (auto id = primitive(prims[p], n > 1 ? base + " #" + std::to_string(p) : base)) ids.push_back(*id);
    meshes_[mi] = std::move(ids);
    return *meshes_[mi];
  }

  // The attribute accessor `key` of a primitive, read as floats into `out` (count elements of N floats).
  template <class V>
  bool attribute(const Json& attrs, const char* key, std::vector<V>& out, uint32_t count, std::initializer_list<int> comps) {
    if (!attrs.get(key)) return false;
    const uint32_t a = attrs.index(key, acc_->accessorCount(), "accessors");
    const uint32_t n = acc_->info(a).count;
    if (n != count)
      attrs.at(key).fail("accessor " + std::to_string(a) + " has " + std::to_string(n) + " elements, POSITION has " +
                         std::to_string(count));
    out.resize(count);
    acc_->readFloats(a, &out[0][0], int(sizeof(V) / sizeof(float)), comps);
    return true;
  }

  std::optional<uint32_t> primitive(const Json& p, const std::string& name) {
    const uint64_t mode = p.uinteger("mode", 4);
    if (mode > 6) p.at("mode").fail(std::to_string(mode) + " is not a primitive mode (0..6)");
    if (p.get("targets")) animated_ = true;
    if (mode < 4) {
      ++skipped_;
      return std::nullopt;
    }
    Mesh m;
    m.name = name;
    m.material =
        mats_->material(p.get("material") ? std::optional(p.index("material", mats_->count(), "materials")) : std::nullopt);
    const Json attrs = p.at("attributes");
    if (!attrs.isObject()) attrs.fail("expected an object");
    std::optional<Json> indicesJ = p.get("indices");
    std::optional<Json> draco;
    if (auto ext = p.get("extensions")) draco = ext->get("KHR_draco_mesh_compression");
    if (draco) {
      readDraco(*draco, m);
      indicesJ = draco;
    } else {
      if (!attrs.get("POSITION")) {
        ++skipped_;
        return std::nullopt;
      }
      const uint32_t pos = attrs.index("POSITION", acc_->accessorCount(), "accessors");
      const uint32_t count = acc_->info(pos).count;
      if (mode == 4 && deferable(p, attrs, indicesJ, count)) {  // its arrays are read after the walk, on all cores
        scene_.meshes.push_back(std::move(m));
        deferred_.push_back({uint32_t(scene_.meshes.size() - 1), p, attrs, indicesJ, count});
        return deferred_.back().mesh;
      }
      for (int stream = 0; stream < kStreams; ++stream) readStream(m, p, attrs, indicesJ, count, stream, false);
    }
    checkIndices(indicesJ ? *indicesJ : p, m);
    checkPositions(attrs, m);
    toTriangleList(p, m.indices.writable(), mode);
    if (m.indices.empty()) {
      ++skipped_;
      return std::nullopt;
    }
    if (!m.normals.empty()) unitNormals(m);
    finishMesh(m);
    scene_.meshes.push_back(std::move(m));
    return uint32_t(scene_.meshes.size() - 1);
  }

  // A triangle list read after the scene's nodes are walked (docs/gltf.md: a GLB's read): what needs no
  // array is checked now, in the walk's order; the arrays then, every stream of every mesh on all cores.
  struct Deferred {
    uint32_t mesh;
    Json p, attrs;
    std::optional<Json> indices;  // none: 0 .. count - 1
    uint32_t count;               // vertices
  };
  static constexpr const char* kAttributes[] = {"POSITION", "NORMAL", "TANGENT", "TEXCOORD_0", "TEXCOORD_1", "COLOR_0"};
  static constexpr int kStreams = 7;  // the attributes, then the indices

  // Checks what can be checked before reading (each attribute's accessor and count, the whole triangles)
  // and resolves the views; false for a list of fewer than 3 indices (read now: it is left out).
  bool deferable(const Json& p, const Json& attrs, const std::optional<Json>& indicesJ, uint32_t count) {
    uint64_t n = count;
    if (indicesJ) {
      const uint32_t a = p.index("indices", acc_->accessorCount(), "accessors");
      n = acc_->info(a).count;
      acc_->prepare(a);
    }
    if (n < 3) return false;
    for (const char* key : kAttributes) {
      if (!attrs.get(key)) continue;
      const uint32_t a = attrs.index(key, acc_->accessorCount(), "accessors");
      if (acc_->info(a).count != count)
        attrs.at(key).fail("accessor " + std::to_string(a) + " has " + std::to_string(acc_->info(a).count) +
                           " elements, POSITION has " + std::to_string(count));
      acc_->prepare(a);
    }
    wholeTriangles(p, n);
    return true;
  }

  // Stream `stream` of a mesh: read, and (deferred) checked on its own.
  void readStream(Mesh& m, const Json& p, const Json& attrs, const std::optional<Json>& indicesJ, uint32_t count, int stream,
                  bool deferred) {
    switch (stream) {
      case 0:
        attribute(attrs, "POSITION", m.positions.writable(), count, {3});
        if (deferred) checkPositions(attrs, m);
        break;
      case 1:
        if (attribute(attrs, "NORMAL", m.normals.writable(), count, {3}) && deferred) unitNormals(m);
        break;
      case 2: attribute(attrs, "TANGENT", m.tangents.writable(), count, {4}); break;
      case 3: attribute(attrs, "TEXCOORD_0", m.texcoords.writable(), count, {2}); break;
      case 4: attribute(attrs, "TEXCOORD_1", m.texcoords1.writable(), count, {2}); break;
      case 5:
        m.colors.assign(attrs.get("COLOR_0") ? count : 0, glm::vec4(1.0f));
        if (!m.colors.empty()) attribute(attrs, "COLOR_0", m.colors.writable(), count, {3, 4});
        break;
      default:
        if (indicesJ) {
          acc_->readIndices(p.index("indices", acc_->accessorCount(), "accessors"), m.indices.writable());
        } else {
          std::vector<uint32_t>& indices = m.indices.writable();
          indices.resize(count);
          std::iota(indices.begin(), indices.end(), 0u);
        }
        if (!deferred) break;
        checkIndices(indicesJ ? *indicesJ : p, m, count);
        m.indices.resize(m.indices.size() - m.indices.size() % 3);  // wholeTriangles warned
    }
  }

  void readDeferred() {
    // Jobs in the order one thread would run them, so the fault reported is the one it would meet first.
    parallelFor(deferred_.size() * kStreams, 0, [&](size_t j) {
      const Deferred& d = deferred_[j / kStreams];
      readStream(scene_.meshes[d.mesh], d.p, d.attrs, d.indices, d.count, int(j % kStreams), true);
    });
    parallelFor(deferred_.size(), 0, [&](size_t i) { finishMesh(scene_.meshes[deferred_[i].mesh]); });
  }

  void checkIndices(const Json& where, const Mesh& m, std::optional<size_t> vertexCount = std::nullopt) {
    const size_t vertices = vertexCount ? *vertexCount : m.positions.size();
    uint32_t maxIndex = 0;
    for (uint32_t i : m.indices) maxIndex = std::max(maxIndex, i);
    if (maxIndex >= vertices && !m.indices.empty()) {
      const size_t i =
          size_t(std::find_if(m.indices.begin(), m.indices.end(), [&](uint32_t v) { return v >= vertices; }) - m.indices.begin());
      where.fail("index " + std::to_string(m.indices[i]) + " (element " + std::to_string(i) + ") is not below the vertex count " +
                 std::to_string(vertices));
    }
  }

  // The one coordinate limit of every reader (core/bounds.hpp): beyond it the squared lengths that
  // clustering and shading take overflow; NaN and infinity are never geometry. Sets the bounds.
  static void checkPositions(const Json& attrs, Mesh& m) {
    for (const glm::vec3& v : m.positions) m.bounds.extend(v);
    const Bounds& bb = m.bounds;
    if (!(std::max({-bb.min.x, -bb.min.y, -bb.min.z, bb.max.x, bb.max.y, bb.max.z}) <= kMaxCoordinate) ||
        !std::all_of(m.positions.begin(), m.positions.end(), [](const glm::vec3& v) { return v == v; }))
      for (size_t i = 0; i < m.positions.size(); ++i) {
        const glm::vec3 v = m.positions[i];
        if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
          attrs.fail("POSITION element " + std::to_string(i) + " is not finite");
        if (std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}) > kMaxCoordinate)
          attrs.fail("POSITION element " + std::to_string(i) +
                     " has a coordinate beyond ±1e12 (the coordinate limit, docs/files-and-cli.md)");
      }
  }

  static void unitNormals(Mesh& m) {  // quantized (or careless) normals are not unit length
    for (glm::vec3& nrm : m.normals.writable()) {
      const float l = glm::length(nrm);
      if (l > 0 && std::isfinite(l)) nrm /= l;
      else nrm = glm::vec3(0, 0, 1);
    }
  }

  // What needs several streams: flat normals where there are none, tangents for a normal map.
  void finishMesh(Mesh& m) const {
    if (m.normals.empty()) flatNormals(m);
    const Material& mat = scene_.materials[m.material];
    const ViewOrVector<glm::vec2>& uv = mat.uv[uint32_t(TextureSlot::NormalMap)].texCoord ? m.texcoords1 : m.texcoords;
    if (m.tangents.empty() && mat.texture(TextureSlot::NormalMap) != kNoTexture && !uv.empty()) generateTangents(m, uv);
  }

  void wholeTriangles(const Json& p, size_t n) {
    if (n % 3)
      warn(p.path() + ": " + std::to_string(n) + " indices of a triangle list are not whole triangles: the last " +
           std::to_string(n % 3) + " left out");
  }

  // Strips and fans as triangle lists (their winding as the spec defines it); a list cut to whole triangles.
  void toTriangleList(const Json& p, std::vector<uint32_t>& idx, uint64_t mode) {
    if (mode == 4) {
      wholeTriangles(p, idx.size());
      idx.resize(idx.size() - idx.size() % 3);
      return;
    }
    std::vector<uint32_t> out;
    for (size_t i = 0; i + 2 < idx.size(); ++i) {
      uint32_t t[3];
      if (mode == 5) {
        t[0] = idx[i];
        t[1] = idx[i + 1 + i % 2];
        t[2] = idx[i + 2 - i % 2];
      } else {
        t[0] = idx[i + 1];
        t[1] = idx[i + 2];
        t[2] = idx[0];
      }
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;  // strip restarts
      out.insert(out.end(), t, t + 3);
    }
    idx = std::move(out);
  }

  void readDraco(const Json& d, Mesh& m) {
    const auto view = acc_->view(d.index("bufferView", acc_->viewCount(), "bufferViews"));
    std::vector<std::pair<std::string, int>> ids;
    d.at("attributes").members([&](std::string_view k, const Json& v) {
      ids.push_back({std::string(k), int(std::min<uint64_t>(v.uinteger(), 1u << 30))});
    });
    gltf::DracoMesh dm;
    try {
      dm = gltf::decodeDraco(view, ids);
    } catch (const Error& e) { d.fail(e.what()); }
    const uint32_t n = dm.vertexCount;
    for (const gltf::DracoAttribute& a : dm.attributes) {
      auto take = [&](auto& out, int want) {
        using V = typename std::decay_t<decltype(out)>::value_type;
        if (a.components < 1 || a.components > want || a.values.size() != size_t(n) * a.components)
          d.at("attributes")
              .at(a.name)
              .fail("the draco data has " + std::to_string(a.components) + " components, expected " + std::to_string(want));
        out.assign(n, V(0.0f));
        for (uint32_t i = 0; i < n; ++i)
          for (int c = 0; c < a.components; ++c) out[i][c] = a.values[size_t(i) * a.components + c];
      };
      if (a.name == "POSITION") take(m.positions.writable(), 3);
      else if (a.name == "NORMAL") take(m.normals.writable(), 3);
      else if (a.name == "TANGENT") take(m.tangents.writable(), 4);
      else if (a.name == "TEXCOORD_0") take(m.texcoords.writable(), 2);
      else if (a.name == "TEXCOORD_1") take(m.texcoords1.writable(), 2);
      else if (a.name == "COLOR_0") {
        take(m.colors.writable(), 4);
        if (a.components == 3)
          for (glm::vec4& c : m.colors.writable()) c.a = 1.0f;
      }
    }
    if (m.positions.empty()) d.fail("the draco data has no POSITION");
    m.indices = std::move(dm.indices);
  }

  void camera(const Json& root, const Json& node, const glm::mat4& world) {
    const Json cams = root.at("cameras");
    const Json c = cams[node.index("camera", cams.size(), "cameras")];
    cameraDone_ = true;
    const glm::vec3 fwd = glm::normalize(glm::vec3(world * glm::vec4(0, 0, -1, 0)));
    const glm::vec3 up = glm::normalize(glm::vec3(world * glm::vec4(0, 1, 0, 0)));
    if (!std::isfinite(fwd.x + fwd.y + fwd.z)) {
      note(node.path() + ": the camera's transform has no direction; the view is framed instead");
      return;
    }
    CameraPose pose;
    pose.position = glm::vec3(world[3]);
    pose.yawDeg = glm::degrees(std::atan2(-fwd.x, -fwd.z));
    pose.pitchDeg = glm::degrees(std::asin(std::clamp(fwd.y, -1.0f, 1.0f)));
    if (std::abs(fwd.y) < 0.999f && glm::dot(basis(pose).up, up) < 0.9995f)
      note(node.path() + ": the camera's roll is dropped (rtr's cameras keep the horizon level)");
    scene_.defaultView = pose;
    const std::string_view type = c.string("type", "");
    if (type == "perspective") {
      const double yfov = c.at("perspective").at("yfov").number();
      if (yfov > 0 && yfov < 3.14159) scene_.defaultFovYDeg = float(glm::degrees(yfov));
    } else {
      note(c.path() + ": an orthographic camera is shown in perspective");
    }
  }

  void light(const Json& root, const Json& ref, const glm::mat4& world) {
    std::optional<Json> ext = root.get("extensions");
    std::optional<Json> lp = ext ? ext->get("KHR_lights_punctual") : std::nullopt;
    if (!lp) ref.fail("names a light, but the file has no KHR_lights_punctual lights");
    const Json lights = lp->at("lights");
    const Json l = lights[ref.index("light", lights.size(), "lights")];
    Light out;
    float color[3] = {1, 1, 1};
    l.numbers("color", color);
    // glTF: point and spot in candela (lm/sr), directional in lux; rtr: colour × intensity, arriving as
    // colour / d² with falloff (docs/gltf.md).
    out.color = glm::vec3(color[0], color[1], color[2]) * float(l.number("intensity", 1.0));
    out.range = float(l.number("range", 0.0));
    out.position = glm::vec3(world[3]);
    const glm::vec3 d = glm::vec3(world * glm::vec4(0, 0, -1, 0));
    out.direction = glm::length(d) > 0 ? glm::normalize(d) : glm::vec3(0, 0, -1);
    const std::string_view type = l.at("type").string();
    if (type == "point") {
      out.kind = Light::Kind::Point;
      out.falloff = true;
    } else if (type == "spot") {
      out.kind = Light::Kind::Spot;
      out.falloff = true;
      const std::optional<Json> spot = l.get("spot");
      const double inner = spot ? spot->number("innerConeAngle", 0.0) : 0.0;
      const double outer = spot ? spot->number("outerConeAngle", M_PI / 4) : M_PI / 4;
      out.innerConeCos = float(std::cos(inner));
      out.outerConeCos = float(std::cos(outer));
    } else if (type == "directional") {
      out.kind = Light::Kind::Directional;
    } else {
      l.at("type").fail("'" + std::string(type) + "' is not point, spot or directional");
    }
    scene_.lights.push_back(out);
  }

  std::string name_;
  std::filesystem::path baseDir_;
  const LoadOptions& opt_;
  Scene scene_;
  gltf::Accessors* acc_ = nullptr;
  gltf::Materials* mats_ = nullptr;
  std::vector<std::optional<std::vector<uint32_t>>> meshes_;
  std::vector<Deferred> deferred_;
  std::set<std::string> said_;
  size_t skipped_ = 0, warnings_ = 0;
  bool animated_ = false, cameraDone_ = false;
};

}  // namespace

Scene parseGltf(std::span<const uint8_t> bytes, const std::string& name, const std::filesystem::path& baseDir,
                const LoadOptions& options) {
  return Loader(name, baseDir, options).run(bytes);
}

Scene loadGltf(const std::filesystem::path& file, const LoadOptions& options) {
  const MappedFile mapped(file);
  return parseGltf(mapped.bytes(), file.string(), file.parent_path(), options);
}

}  // namespace rtr
