#include "scene/obj.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>
#include <unordered_map>

#include "core/error.hpp"
#include "scene/mtl.hpp"
#include "scene/text.hpp"
#include "scene/weld.hpp"

namespace rtr {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

constexpr size_t kChunk = size_t(4) << 20;
constexpr size_t kMaxLine = size_t(64) << 20;
constexpr size_t kMaxName = 32767;

struct MeshBuild {
  std::string name;
  uint32_t material = 0;
  std::vector<Corner> corners;
};

class ObjParser {
public:
  ObjParser(const std::string& name, const MtlReader& readMtl, const ObjOptions& options, ObjStats& stats)
      : name_(name), readMtl_(readMtl), opt_(options), stats_(stats) {}

  void run(ByteSource& src) {
    // Small inputs (tests, fuzzing) get a small buffer; it grows for long lines.
    std::vector<char> buf(std::min<uint64_t>(kChunk, std::max<uint64_t>(65536, src.fileSize())));
    size_t have = 0;
    for (;;) {
      if (have == buf.size()) {
        if (buf.size() >= kMaxLine) throw error("line longer than " + std::to_string(kMaxLine) + " bytes");
        buf.resize(buf.size() * 2);
      }
      const size_t got = src.read(buf.data() + have, buf.size() - have);
      stats_.textBytes += got;
      have += got;
      size_t start = 0;
      for (;;) {
        const void* nl = std::memchr(buf.data() + start, '\n', have - start);
        if (!nl) break;
        const size_t end = size_t(static_cast<const char*>(nl) - buf.data());
        ++line_;
        onLine(std::string_view(buf.data() + start, end - start));
        start = end + 1;
      }
      if (got == 0) {
        if (start < have) {
          ++line_;
          onLine(std::string_view(buf.data() + start, have - start));
        }
        break;
      }
      std::memmove(buf.data(), buf.data() + start, have - start);
      have -= start;
      if (opt_.progress) opt_.progress(src.consumed(), src.fileSize());
    }
  }

  Scene finish();

private:
  Error error(const std::string& what) const { return fileError(name_, std::to_string(line_), what); }
  void warn(const std::string& what) {
    ++stats_.warnings;
    const std::string msg = name_ + ":" + std::to_string(line_) + ": " + what;
    if (opt_.warn) opt_.warn(msg);
    else std::cerr << "warning: " << msg << "\n";
  }

  std::string checkedName(std::string_view what, std::string_view s) {
    s = text::trim(s);
    if (s.size() > kMaxName) throw error(std::string(what) + " longer than " + std::to_string(kMaxName) + " bytes");
    if (!text::validUtf8(s)) throw error(std::string(what) + " is not valid UTF-8");
    return std::string(s);
  }

  template <int N, class V>
  void vec(std::string_view rest, std::vector<V>& out, const char* key, int required) {
    V v(0.0f);
    for (int i = 0; i < N; ++i) {
      float f = 0;
      switch (text::nextFloat(rest, f)) {
        case text::NumResult::Ok: v[i] = f; break;
        case text::NumResult::Missing:
          if (i < required) throw error(std::string("'") + key + "' needs " + std::to_string(required) + " numbers");
          i = N;
          break;
        case text::NumResult::NotFinite: throw error(std::string("'") + key + "' coordinate is NaN or infinite");
        default: throw error(std::string("'") + key + "' coordinate is not a number");
      }
    }
    out.push_back(v);
  }

  void onLine(std::string_view l) {
    size_t i = 0;
    while (i < l.size() && text::isSpace(l[i])) ++i;
    if (i == l.size()) return;
    const char c0 = l[i];
    const char c1 = i + 1 < l.size() ? l[i + 1] : '\0';
    const bool sep1 = c1 == '\0' || text::isSpace(c1);
    if (c0 == 'v' && sep1) return vec<3>(l.substr(i + 1), positions_, "v", 3);
    if (c0 == 'f' && sep1) return face(l.substr(i + 1));
    if (c0 == 'v' && c1 == 'n' && (i + 2 == l.size() || text::isSpace(l[i + 2]))) return vec<3>(l.substr(i + 2), normals_, "vn", 3);
    if (c0 == 'v' && c1 == 't' && (i + 2 == l.size() || text::isSpace(l[i + 2]))) return vec<2>(l.substr(i + 2), texcoords_, "vt", 1);
    if (c0 == '#') return;
    std::string_view rest = l.substr(i);
    const std::string_view key = text::nextToken(rest);
    if (key == "o" || key == "g") {
      std::string n = checkedName("object name", rest);
      if (n.empty()) n = "default";
      groupsSeen_ = true;
      auto [it, added] = objectIds_.try_emplace(n, uint32_t(objectNames_.size()));
      if (added) objectNames_.push_back(n);
      object_ = it->second;
      mesh_ = kAbsent;
    } else if (key == "usemtl") {
      material_ = materialId(checkedName("material name", rest), true);
      if (!groupsSeen_) {  // no o/g lines: each usemtl run is an object (the ray tracer's lights)
        object_ = uint32_t(objectNames_.size());
        objectNames_.push_back(materials_[material_].material.name);
      }
      mesh_ = kAbsent;
    } else if (key == "mtllib") {
      loadMtl(checkedName("mtllib file name", rest));
    } else if (key == "s" || key == "l" || key == "p" || key == "cstype" || key == "vp") {
      // smoothing groups, lines and points carry nothing for triangle meshes
    } else if (std::find(unknown_.begin(), unknown_.end(), key) == unknown_.end()) {
      unknown_.emplace_back(key.substr(0, 64));
      warn("unknown OBJ keyword '" + std::string(key.substr(0, 64)) + "' ignored");
    }
  }

  uint32_t materialId(const std::string& n, bool warnIfNew) {
    auto it = materialIds_.find(n);
    if (it != materialIds_.end()) return it->second;
    if (warnIfNew) warn("material '" + n + "' is not defined in any MTL; using default values");
    MtlMaterial m;
    m.material.name = n;
    m.material.flags = flagsFromName(n);
    materials_.push_back(std::move(m));
    materialIds_.emplace(n, uint32_t(materials_.size() - 1));
    return uint32_t(materials_.size() - 1);
  }

  void loadMtl(const std::string& file) {
    if (file.empty()) throw error("'mtllib' names no file");
    if (std::find(mtlFiles_.begin(), mtlFiles_.end(), file) != mtlFiles_.end()) return;
    mtlFiles_.push_back(file);
    const std::string textMtl = readMtl_(file);
    auto ws = [this](const std::string& w) {
      ++stats_.warnings;
      if (opt_.warn) opt_.warn(w);
      else std::cerr << "warning: " << w << "\n";
    };
    for (MtlMaterial& m : parseMtl(textMtl, file, ws)) {
      auto it = materialIds_.find(m.material.name);
      if (it == materialIds_.end()) {
        materialIds_.emplace(m.material.name, uint32_t(materials_.size()));
        materials_.push_back(std::move(m));
      } else {
        ws(file + ": material '" + m.material.name + "' defined again; the later definition wins");
        materials_[it->second] = std::move(m);
      }
    }
  }

  // Parses one signed index; returns false at the end of the token.
  static bool parseIndex(const char*& p, const char* e, int64_t& v) {
    bool neg = false;
    if (p < e && *p == '-') { neg = true; ++p; }
    const char* s = p;
    int64_t x = 0;
    while (p < e && unsigned(*p - '0') < 10u) {
      x = x * 10 + (*p - '0');
      if (x > (int64_t(1) << 40)) return false;
      ++p;
    }
    if (p == s) return false;
    v = neg ? -x : x;
    return true;
  }

  uint32_t resolve(int64_t idx, size_t count, const char* what) {
    if (idx == 0) throw error(std::string("face ") + what + " index 0 is invalid (OBJ indices start at 1)");
    int64_t r = idx > 0 ? idx - 1 : int64_t(count) + idx;
    if (r < 0 || r >= int64_t(count))
      throw error(std::string("face ") + what + " index " + std::to_string(idx) + " out of range (" +
                  std::to_string(count) + " " + what + "s defined so far)");
    return uint32_t(r);
  }

  void face(std::string_view rest) {
    poly_.clear();
    const char* p = rest.data();
    const char* e = p + rest.size();
    for (;;) {
      while (p < e && text::isSpace(*p)) ++p;
      if (p == e) break;
      Corner c{kAbsent, kAbsent, kAbsent};
      int64_t v;
      if (!parseIndex(p, e, v)) throw error("face corner is not an index (expected v, v/vt, v//vn or v/vt/vn)");
      c.p = resolve(v, positions_.size(), "position");
      if (p < e && *p == '/') {
        ++p;
        if (p < e && *p != '/') {
          if (!parseIndex(p, e, v)) throw error("face texture coordinate index is not a number");
          c.t = resolve(v, texcoords_.size(), "texcoord");
        }
        if (p < e && *p == '/') {
          ++p;
          if (!parseIndex(p, e, v)) throw error("face normal index is not a number");
          c.n = resolve(v, normals_.size(), "normal");
        }
      }
      if (p < e && !text::isSpace(*p)) throw error("unexpected character in face corner");
      poly_.push_back(c);
    }
    ++stats_.faces;
    if (poly_.size() < 3) {
      stats_.degenerateSkipped += 1;
      return;
    }
    if (mesh_ == kAbsent) mesh_ = currentMesh();
    auto& corners = builds_[mesh_].corners;
    for (size_t k = 1; k + 1 < poly_.size(); ++k) corners.insert(corners.end(), {poly_[0], poly_[k], poly_[k + 1]});
  }

  uint32_t currentMesh() {
    if (material_ == kAbsent) material_ = materialId("default", false);
    if (object_ == kAbsent) {
      object_ = uint32_t(objectNames_.size());
      objectNames_.push_back(groupsSeen_ ? "default" : materials_[material_].material.name);
    }
    const uint64_t key = (uint64_t(object_) << 32) | material_;
    auto [it, added] = meshIds_.try_emplace(key, uint32_t(builds_.size()));
    if (added) builds_.push_back({objectNames_[object_], material_, {}});
    return it->second;
  }

  std::string name_;
  const MtlReader& readMtl_;
  const ObjOptions& opt_;
  ObjStats& stats_;
  size_t line_ = 0;

  std::vector<glm::vec3> positions_, normals_;
  std::vector<glm::vec2> texcoords_;
  std::vector<Corner> poly_;
  std::vector<MeshBuild> builds_;
  std::unordered_map<uint64_t, uint32_t> meshIds_;
  std::vector<std::string> objectNames_;
  std::unordered_map<std::string, uint32_t> objectIds_;
  std::vector<MtlMaterial> materials_;
  std::unordered_map<std::string, uint32_t> materialIds_;
  std::vector<std::string> mtlFiles_, unknown_;
  uint32_t object_ = kAbsent, material_ = kAbsent, mesh_ = kAbsent;
  bool groupsSeen_ = false;
};

Scene ObjParser::finish() {
  stats_.positions = positions_.size();
  stats_.normals = normals_.size();
  stats_.texcoords = texcoords_.size();
  Scene scene;

  // Texture ids at first appearance: materials in MTL order, slots in the course order; paths de-duplicated.
  std::unordered_map<std::string, uint32_t> texIds;
  for (MtlMaterial& m : materials_) {
    for (uint32_t s = 0; s < kTextureSlotCount; ++s) {
      const std::string& file = m.maps[s];
      if (file.empty()) continue;
      auto [it, added] = texIds.try_emplace(file, uint32_t(scene.textures.size()));
      if (added) {
        const SlotFormat f = slotFormat(TextureSlot(s));
        scene.textures.push_back({std::filesystem::path(file), f.srgb, f.channels});
      }
      m.material.textures[s] = it->second;
    }
    scene.materials.push_back(std::move(m.material));
  }

  // Weld meshes on a few threads; big meshes dominate, so hand them out one at a time.
  std::vector<Mesh> meshes(builds_.size());
  std::vector<WeldCounts> counts(builds_.size());
  std::atomic<size_t> nextMesh{0};
  auto worker = [&] {
    for (size_t i; (i = nextMesh.fetch_add(1)) < builds_.size();) {
      counts[i] = weldMesh(builds_[i].corners, positions_, normals_, texcoords_, meshes[i]);
      std::vector<Corner>().swap(builds_[i].corners);
    }
  };
  unsigned n = opt_.threads ? opt_.threads : std::max(1u, std::thread::hardware_concurrency());
  n = unsigned(std::min<size_t>(n, builds_.size()));
  std::vector<std::exception_ptr> errors(n);
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < n; ++t)
    pool.emplace_back([&, t] { try { worker(); } catch (...) { errors[t] = std::current_exception(); } });
  try { worker(); } catch (...) { if (n) errors[0] = std::current_exception(); }
  for (auto& t : pool) t.join();
  for (auto& e : errors) if (e) std::rethrow_exception(e);

  for (size_t i = 0; i < builds_.size(); ++i) {
    stats_.verticesBeforeWeld += (counts[i].triangles + counts[i].degenerate) * 3;
    stats_.degenerateSkipped += counts[i].degenerate;
    stats_.triangles += counts[i].triangles;
    stats_.verticesAfterWeld += counts[i].vertices;
    if (meshes[i].indices.empty()) continue;  // nothing but degenerate faces
    meshes[i].name = builds_[i].name;
    meshes[i].material = builds_[i].material;
    scene.meshes.push_back(std::move(meshes[i]));
  }
  return scene;
}

std::string readWholeFile(const std::filesystem::path& file, const std::string& what) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw fileError(file.string(), "", "cannot open " + what + ": " + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw fileError(file.string(), "", "read error");
  return std::move(ss).str();
}

}  // namespace

Scene parseObj(ByteSource& source, const std::string& name, const MtlReader& readMtl, const ObjOptions& options,
               ObjStats* stats) {
  ObjStats local;
  ObjStats& st = stats ? *stats : local;
  st.fileBytes = source.fileSize();
  ObjParser parser(name, readMtl, options, st);
  auto t0 = Clock::now();
  parser.run(source);
  st.parseSeconds = since(t0);
  t0 = Clock::now();
  Scene scene = parser.finish();
  st.weldSeconds = since(t0);
  return scene;
}

Scene loadObj(const std::filesystem::path& file, const ObjOptions& options, ObjStats* stats) {
  auto src = openSource(file);
  const std::filesystem::path dir = file.parent_path();
  MtlReader readMtl = [&](const std::string& mtl) {
    const std::filesystem::path p = dir / mtl;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(p, ec))
      throw fileError(file.string(), "", "material library '" + p.string() + "' named by 'mtllib' does not exist");
    return readWholeFile(p, "material library");
  };
  Scene scene = parseObj(*src, file.string(), readMtl, options, stats);
  scene.baseDir = dir;
  return scene;
}

}  // namespace rtr
