#include "scene/obj.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <optional>
#include <thread>
#include <sstream>
#include <unordered_map>

#include "core/bounds.hpp"
#include "core/error.hpp"
#include "core/input_file.hpp"
#include "core/parallel.hpp"
#include "scene/mtl.hpp"
#include "scene/text.hpp"
#include "scene/triangulate.hpp"
#include "scene/weld.hpp"

namespace rtr {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

constexpr size_t kChunk = size_t(4) << 20;
constexpr size_t kMaxLine = size_t(64) << 20;
constexpr size_t kMaxName = 32767;
constexpr uint64_t kMaxMtlBytes = uint64_t(64) << 20;  // real ones are kilobytes; /dev/zero is refused anyway
constexpr size_t kShownWarnings = 10;
constexpr size_t kSniffBytes = 8192;  // how much of the start is checked for being text, as git does

struct MeshBuild {
  std::string name;
  uint32_t material = 0;
  std::vector<Corner> corners;
};

class ObjParser {
 public:
  ObjParser(const std::string& name, const MtlReader& readMtl, const ObjOptions& options, ObjStats& stats,
            const std::string& besideMtl)
      : name_(name), readMtl_(readMtl), opt_(options), stats_(stats), besideMtl_(besideMtl) {}

  void run(ByteSource& src) {
    if (opt_.mtl) {
      const std::string given = opt_.mtl->string();
      if (!loadMtl(given, given)) throw fileError(given, "", "MTL file given for '" + name_ + "' does not exist");
      mtlSeen_ = true;
    }
    // Small inputs (tests, fuzzing) get a small buffer; it grows for long lines.
    std::vector<char> buf(std::min<uint64_t>(kChunk, std::max<uint64_t>(65536, src.fileSize())));
    size_t have = 0;
    for (;;) {
      if (have == buf.size()) {
        if (buf.size() >= kMaxLine) throw error("line longer than " + std::to_string(kMaxLine) + " bytes");
        buf.resize(buf.size() * 2);
      }
      const size_t got = src.read(buf.data() + have, buf.size() - have);
      if (stats_.textBytes < kSniffBytes) sniff(std::string_view(buf.data() + have, got), stats_.textBytes);
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
  void warn(const std::string& what) { warnRaw(name_ + ":" + std::to_string(line_) + ": " + what); }
  // Every warning is counted; the first few are passed on, finish() reports the total.
  void warnRaw(const std::string& msg) {
    if (++stats_.warnings > kShownWarnings) return;
    if (opt_.warn) opt_.warn(msg);
    else std::cerr << "warning: " << msg << "\n";
  }
  void note(const std::string& msg) {
    if (opt_.note) opt_.note(msg);
    else std::cerr << "note: " << msg << "\n";
  }

  // Text OBJ is ASCII or any 8-bit encoding; UTF-16 and binary data would otherwise parse as nothing.
  void sniff(std::string_view data, uint64_t offset) {
    if (offset == 0 && data.size() >= 2 && ((data[0] == '\xFE' && data[1] == '\xFF') || (data[0] == '\xFF' && data[1] == '\xFE')))
      throw fileError(name_, "", "UTF-16 text (byte order mark); an OBJ file must be ASCII or UTF-8");
    for (size_t i = 0; i < data.size() && offset + i < kSniffBytes; ++i) {
      const unsigned char c = static_cast<unsigned char>(data[i]);
      if (c < 0x20 && c != '\n' && !text::isSpace(char(c)) && c != 0x1A) {  // 0x1A: DOS end-of-file mark
        char hex[8];
        std::snprintf(hex, sizeof hex, "0x%02X", c);
        throw fileError(name_, "byte " + std::to_string(offset + i),
                        std::string("control byte ") + hex + ": binary data, not a text OBJ file");
      }
    }
  }

  // Names are bytes in whatever encoding the exporter used; only their length is limited.
  std::string checkedName(std::string_view what, std::string_view s) {
    s = text::trim(s);
    if (s.size() > kMaxName) throw error(std::string(what) + " longer than " + std::to_string(kMaxName) + " bytes");
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
    if constexpr (N == 3)
      if (key[1] == '\0' && !coordinateOk(v))  // 'v': the limit every reader applies
        throw error("vertex coordinate beyond ±1e12 (the coordinate limit, docs/files-and-cli.md)");
    out.push_back(v);
  }

  // `v x y z`, or `v x y z r g b` (vertex colours, as other readers take them; a lone 4th number is w).
  // What follows the third number is read only as colour: anything else there is ignored, as before.
  void vertex(std::string_view rest) {
    float f[6] = {};
    int n = 0;
    for (; n < 6; ++n) {
      const text::NumResult r = text::nextFloat(rest, f[n]);
      if (r == text::NumResult::Ok) continue;
      if (n >= 3) break;
      if (r == text::NumResult::Missing) throw error("'v' needs 3 numbers");
      if (r == text::NumResult::NotFinite) throw error("'v' coordinate is NaN or infinite");
      throw error("'v' coordinate is not a number");
    }
    if (!coordinateOk(glm::vec3(f[0], f[1], f[2])))  // the limit every reader applies
      throw error("vertex coordinate beyond ±1e12 (the coordinate limit, docs/files-and-cli.md)");
    positions_.push_back({f[0], f[1], f[2]});
    const bool coloured = n == 6;
    if (coloured && colors_.size() < positions_.size() - 1) colors_.assign(positions_.size() - 1, glm::vec4(1.0f));
    if (coloured || !colors_.empty()) colors_.push_back(coloured ? glm::vec4(f[3], f[4], f[5], 1.0f) : glm::vec4(1.0f));
  }

  void onLine(std::string_view l) {
    if (line_ == 1 && l.substr(0, 3) == "\xEF\xBB\xBF") l.remove_prefix(3);  // UTF-8 byte order mark
    size_t i = 0;
    while (i < l.size() && text::isSpace(l[i])) ++i;
    if (i == l.size()) return;
    const char c0 = l[i];
    const char c1 = i + 1 < l.size() ? l[i + 1] : '\0';
    const bool sep1 = c1 == '\0' || text::isSpace(c1);
    if (c0 == 'v' && sep1) return vertex(l.substr(i + 1));
    if (c0 == 'f' && sep1) return face(l.substr(i + 1));
    if (c0 == 'v' && c1 == 'n' && (i + 2 == l.size() || text::isSpace(l[i + 2])))
      return vec<3>(l.substr(i + 2), normals_, "vn", 3);
    if (c0 == 'v' && c1 == 't' && (i + 2 == l.size() || text::isSpace(l[i + 2])))
      return vec<2>(l.substr(i + 2), texcoords_, "vt", 1);
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
      if (!mtlSeen_ && !besideMtl_.empty()) {  // no mtllib: the course's NAME.mtl convention
        mtlSeen_ = true;
        if (loadMtl(besideMtl_, mtlLabel(besideMtl_)))
          note(name_ + ": no 'mtllib' line; using '" + mtlLabel(besideMtl_) + "' beside it");
      }
      material_ = materialId(checkedName("material name", rest), true);
      if (!groupsSeen_) {  // no o/g lines: each usemtl run is an object (the ray tracer's lights)
        object_ = uint32_t(objectNames_.size());
        objectNames_.push_back(materials_[material_].material.name);
      }
      mesh_ = kAbsent;
    } else if (key == "mtllib") {
      const std::string file = checkedName("mtllib file name", rest);
      if (file.empty()) throw error("'mtllib' names no file");
      if (opt_.mtl) {
        if (!mtllibIgnored_)
          note(name_ + ":" + std::to_string(line_) + ": 'mtllib " + file + "' ignored; using '" + opt_.mtl->string() +
               "' as given");
        mtllibIgnored_ = true;
      } else if (!loadMtl(file, mtlLabel(file))) {
        warn("material library '" + mtlLabel(file) + "' named by 'mtllib' does not exist; its materials get default values");
      }
      mtlSeen_ = true;
    } else if (key == "l" || key == "p") {
      ++pointsAndLines_;  // nothing to draw for triangle meshes; one note at the end
    } else if (key == "s" || key == "cstype" || key == "vp") {
      // smoothing groups and free-form data carry nothing for triangle meshes
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

  // An MTL's path for messages: beside the OBJ (given MTLs are named as given).
  std::string mtlLabel(const std::string& file) const { return (std::filesystem::path(name_).parent_path() / file).string(); }

  // Reads the MTL `file` (as the reader knows it) once; false when it does not exist.
  bool loadMtl(const std::string& file, const std::string& label) {
    if (std::find(mtlFiles_.begin(), mtlFiles_.end(), file) != mtlFiles_.end()) return true;
    mtlFiles_.push_back(file);
    const std::optional<std::string> textMtl = readMtl_(file);
    if (!textMtl) return false;
    auto ws = [this](const std::string& w) { warnRaw(w); };
    for (MtlMaterial& m : parseMtl(*textMtl, label, ws)) {
      auto it = materialIds_.find(m.material.name);
      if (it == materialIds_.end()) {
        materialIds_.emplace(m.material.name, uint32_t(materials_.size()));
        materials_.push_back(std::move(m));
      } else {
        ws(label + ": material '" + m.material.name + "' defined again; the later definition wins");
        materials_[it->second] = std::move(m);
      }
    }
    return true;
  }

  // Parses one signed index; returns false at the end of the token.
  static bool parseIndex(const char*& p, const char* e, int64_t& v) {
    bool neg = false;
    if (p < e && *p == '-') {
      neg = true;
      ++p;
    }
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

  // A texcoord or normal index that points nowhere: kAbsent (the face loses that attribute; one warning).
  uint32_t resolveLenient(int64_t idx, size_t count, const char* what, bool& dropped) {
    const int64_t r = idx > 0 ? idx - 1 : int64_t(count) + idx;
    if (idx != 0 && r >= 0 && r < int64_t(count)) return uint32_t(r);
    if (!dropped && ++danglingFaces_ == 1)
      warn(std::string("face ") + what + " index " + std::to_string(idx) + " points nowhere (" + std::to_string(count) + " " +
           what + "s defined so far): the face's " + what + "s are dropped" +
           (std::string(what) == "normal" ? " and computed" : "") + " (so for every such face; no more warnings)");
    dropped = true;
    return kAbsent;
  }

  uint32_t resolve(int64_t idx, size_t count, const char* what) {
    if (idx == 0) throw error(std::string("face ") + what + " index 0 is invalid (OBJ indices start at 1)");
    int64_t r = idx > 0 ? idx - 1 : int64_t(count) + idx;
    if (r < 0 || r >= int64_t(count))
      throw error(std::string("face ") + what + " index " + std::to_string(idx) + " out of range (" + std::to_string(count) +
                  " " + what + "s defined so far)");
    return uint32_t(r);
  }

  void face(std::string_view rest) {
    poly_.clear();
    bool dropT = false, dropN = false;
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
          c.t = resolveLenient(v, texcoords_.size(), "texcoord", dropT);
        }
        if (p < e && *p == '/') {
          ++p;
          if (!parseIndex(p, e, v)) throw error("face normal index is not a number");
          c.n = resolveLenient(v, normals_.size(), "normal", dropN);
        }
      }
      if (p < e && !text::isSpace(*p)) throw error("unexpected character in face corner");
      poly_.push_back(c);
    }
    for (Corner& c : poly_) {
      if (dropT) c.t = kAbsent;
      if (dropN) c.n = kAbsent;
    }
    ++stats_.faces;
    if (poly_.size() < 3) {
      stats_.degenerateSkipped += 1;
      return;
    }
    if (mesh_ == kAbsent) mesh_ = currentMesh();
    auto& corners = builds_[mesh_].corners;
    if (poly_.size() == 3) {
      corners.insert(corners.end(), poly_.begin(), poly_.end());
      return;
    }
    polyPos_.clear();
    for (const Corner& c : poly_) polyPos_.push_back(positions_[c.p]);
    tris_.clear();
    if (!triangulatePolygon(polyPos_, tris_))
      warn("polygon of " + std::to_string(poly_.size()) + " corners crosses itself; part of it fan-triangulated");
    for (const auto& t : tris_) corners.insert(corners.end(), {poly_[t[0]], poly_[t[1]], poly_[t[2]]});
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
  std::vector<glm::vec4> colors_;  // one per position once a `v` line has a colour; empty before
  std::vector<glm::vec2> texcoords_;
  std::vector<Corner> poly_;
  std::vector<glm::vec3> polyPos_;
  std::vector<std::array<uint32_t, 3>> tris_;
  std::vector<MeshBuild> builds_;
  std::unordered_map<uint64_t, uint32_t> meshIds_;
  std::vector<std::string> objectNames_;
  std::unordered_map<std::string, uint32_t> objectIds_;
  std::vector<MtlMaterial> materials_;
  std::unordered_map<std::string, uint32_t> materialIds_;
  std::vector<std::string> mtlFiles_, unknown_;
  std::string besideMtl_;
  uint32_t object_ = kAbsent, material_ = kAbsent, mesh_ = kAbsent;
  bool groupsSeen_ = false, mtlSeen_ = false, mtllibIgnored_ = false;
  size_t pointsAndLines_ = 0, danglingFaces_ = 0;
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
  parallelFor(builds_.size(), opt_.threads, [&](size_t i) {
    counts[i] = weldMesh(builds_[i].corners, positions_, normals_, texcoords_, meshes[i], opt_.creaseDeg, colors_);
    std::vector<Corner>().swap(builds_[i].corners);
  });

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

  const std::string skipped = std::to_string(pointsAndLines_) + " point/line element(s)";
  if (pointsAndLines_ && !scene.meshes.empty()) note(name_ + ": " + skipped + " skipped; only faces are drawn");
  if (stats_.warnings > kShownWarnings && opt_.warn)
    opt_.warn(name_ + ": " + std::to_string(stats_.warnings) + " warnings, first " + std::to_string(kShownWarnings) + " shown");
  else if (stats_.warnings > kShownWarnings)
    std::cerr << "warning: " << name_ << ": " << stats_.warnings << " warnings, first " << kShownWarnings << " shown\n";
  if (scene.meshes.empty())
    throw fileError(name_, "",
                    stats_.faces      ? "all " + std::to_string(stats_.faces) + " faces are degenerate; nothing to draw"
                    : pointsAndLines_ ? "no faces, only " + skipped + "; nothing to draw"
                                      : "no faces; nothing to draw (is it an OBJ file?)");
  return scene;
}

}  // namespace

Scene parseObj(ByteSource& source, const std::string& name, const MtlReader& readMtl, const ObjOptions& options, ObjStats* stats,
               const std::string& besideMtl) {
  ObjStats local;
  ObjStats& st = stats ? *stats : local;
  st.fileBytes = source.fileSize();
  ObjParser parser(name, readMtl, options, st, besideMtl);
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
  MtlReader readMtl = [&](const std::string& mtl) -> std::optional<std::string> {
    const std::filesystem::path p = options.mtl && mtl == options.mtl->string() ? *options.mtl : dir / mtl;
    std::error_code ec;
    if (!std::filesystem::exists(p, ec)) return std::nullopt;
    return readInputFile(p, "material library", kMaxMtlBytes);
  };
  // NAME.mtl for NAME.obj, NAME.obj.zst and NAME.obj-zstd.
  std::string stem = file.filename().string();
  for (std::string_view ext : {".obj.zst", ".obj-zstd", ".obj"})
    if (stem.size() > ext.size() && stem.compare(stem.size() - ext.size(), ext.size(), ext) == 0) {
      stem.resize(stem.size() - ext.size());
      break;
    }
  std::error_code ec;
  const std::string beside = std::filesystem::is_regular_file(dir / (stem + ".mtl"), ec) ? stem + ".mtl" : "";
  Scene scene = parseObj(*src, file.string(), readMtl, options, stats, beside);
  scene.baseDir = dir;
  return scene;
}

}  // namespace rtr
