#include "scene/obj.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <iostream>
#include <malloc.h>
#include <optional>
#include <thread>
#include <sstream>
#include <unordered_map>

#include "core/bounds.hpp"
#include "core/env.hpp"
#include "core/error.hpp"
#include "core/input_file.hpp"
#include "core/parallel.hpp"
#include "scene/grow_array.hpp"
#include "scene/mtl.hpp"
#include "scene/obj_piece.hpp"
#include "scene/text.hpp"
#include "scene/weld.hpp"

namespace rtr {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
double cpuSince(std::clock_t c) { return double(std::clock() - c) / CLOCKS_PER_SEC; }

// The text is read in batches of whole lines and parsed in pieces of about kPieceBytes on all cores.
// Both are fixed, so the pieces do not depend on the thread count (and a wrong stitch shows with any).
constexpr size_t kBatch = size_t(64) << 20;
// Pieces of 256 KiB, 256 a batch: a step over a batch's pieces waits for its last piece on the other cores, at
// 1 MiB (64 a batch, 4 a thread on 16) the parse's resolve left 7 of 16 cores idle at 100 M.
// RTR_OBJ_PIECE_KIB=N sets it for measuring (the parse is the same for any).
constexpr size_t kPieceBytes = size_t(256) << 10;
size_t pieceBytesFromEnv() {
  const auto kib = envNumber("RTR_OBJ_PIECE_KIB", 1, 1u << 20, "a piece size in KiB");
  return kib ? size_t(*kib) << 10 : kPieceBytes;
}
constexpr size_t kMaxLine = size_t(64) << 20;
constexpr uint64_t kMaxMtlBytes = uint64_t(64) << 20;  // real ones are kilobytes; /dev/zero is refused anyway
constexpr size_t kShownWarnings = 10;
constexpr size_t kLargeMesh = size_t(1) << 20;  // corners: a mesh welded on all cores
constexpr size_t kSniffBytes = 8192;            // how much of the start is checked for being text, as git does

struct MeshBuild {
  std::string name;
  uint32_t material = 0;
  GrowArray<Corner> corners;
  size_t queued = 0;                                         // corners given a place so far
  std::array<uint32_t, 3> least{kAbsent, kAbsent, kAbsent};  // the smallest p, t and n of its corners
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
    const size_t pieceBytes = opt_.pieceBytes ? opt_.pieceBytes : pieceBytesFromEnv();
    // Small inputs (tests, fuzzing) get a small buffer; it grows for long lines.
    std::vector<char> buf(std::min<uint64_t>(kBatch, std::max<uint64_t>(65536, src.fileSize()))), next;
    size_t have = 0;
    bool atEnd = false, fileStart = true;
    auto fill = [&](std::vector<char>& b, size_t& n) {  // full batches: where pieces end depends on the text only
      while (!atEnd && n < b.size()) {
        const size_t got = src.read(b.data() + n, b.size() - n);
        if (stats_.textBytes < kSniffBytes) sniff(std::string_view(b.data() + n, got), stats_.textBytes);
        stats_.textBytes += got;
        n += got;
        atEnd = got == 0;
      }
    };
    auto t = Clock::now();
    step("parse: the first text read");
    fill(buf, have);
    stats_.textWaitSeconds += since(t);
    while (have) {
      const std::string_view text(buf.data(), have);
      size_t end = have;  // the batch: whole lines (a continued line is one)
      if (!atEnd) {
        end = objpiece::lastLineEnd(text);
        if (end == 0) {
          if (buf.size() >= kMaxLine) throw error("line longer than " + std::to_string(kMaxLine) + " bytes");
          buf.resize(std::min(buf.size() * 2, kMaxLine));
          fill(buf, have);
          continue;
        }
      }
      std::vector<objpiece::Piece> pieces;
      for (size_t at = 0; at < end;) {
        const size_t e = std::min(end, objpiece::pieceEnd(text, std::min(end, at + pieceBytes)));
        pieces.emplace_back();
        pieces.back().text = text.substr(at, e - at);
        pieces.back().fileStart = fileStart && at == 0;
        at = e;
      }
      fileStart = false;
      // The next batch is read while this one is parsed; the parse is index 0, so its error comes first.
      next.resize(buf.size());
      size_t nextHave = have - end;
      std::memcpy(next.data(), buf.data() + end, nextHave);
      double parsed = 0;
      t = Clock::now();
      parallelFor(2, opt_.threads, [&](size_t i) {
        if (i != 0) return fill(next, nextHave);
        const auto p = Clock::now();
        parseBatch(pieces);
        parsed = since(p);
        step("parse: waiting for the text");
      });
      stats_.textWaitSeconds += since(t) - parsed;
      std::swap(buf, next);
      have = nextHave;
      if (opt_.progress) opt_.progress(src.consumed(), src.fileSize());
    }
  }

  Scene finish();

 private:
  void step(const char* name) const {
    if (opt_.step) opt_.step(name);
  }
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

  // Parses the pieces on all cores, appends their records, resolves their faces on all cores, then
  // replays their events in file order.
  void parseBatch(std::vector<objpiece::Piece>& pieces) {
    step("parse: pieces");
    parallelFor(pieces.size(), opt_.threads, [&](size_t i) { objpiece::parsePiece(pieces[i]); });
    // Where each piece's records go (serial, a few numbers a piece), then copied there on all cores.
    step("parse: records placed (one thread)");
    std::vector<objpiece::Counts> before(pieces.size());
    objpiece::Counts end{positions_.size(), texcoords_.size(), normals_.size()};
    for (size_t i = 0; i < pieces.size(); ++i) {
      before[i] = end;
      end.positions += pieces[i].positions.size();
      end.texcoords += pieces[i].texcoords.size();
      end.normals += pieces[i].normals.size();
      coloured_ = coloured_ || !pieces[i].colors.empty();
    }
    // The arrays grow without a pass over them (GrowArray); the pieces' records are copied in on all cores.
    const size_t uncoloured = colors_.size();  // colours begin in this batch: white for the positions before
    positions_.resize(end.positions);
    texcoords_.resize(end.texcoords);
    normals_.resize(end.normals);
    if (coloured_) colors_.resize(end.positions);
    if (coloured_ && before.size())
      std::fill(colors_.begin() + uncoloured, colors_.begin() + before[0].positions, glm::vec4(1.0f));
    step("parse: records copied");
    parallelFor(pieces.size(), opt_.threads, [&](size_t i) {
      objpiece::Piece& p = pieces[i];
      std::copy(p.positions.begin(), p.positions.end(), positions_.begin() + ptrdiff_t(before[i].positions));
      std::copy(p.texcoords.begin(), p.texcoords.end(), texcoords_.begin() + ptrdiff_t(before[i].texcoords));
      std::copy(p.normals.begin(), p.normals.end(), normals_.begin() + ptrdiff_t(before[i].normals));
      if (coloured_ && p.colors.empty())  // white where a `v` had no colour
        std::fill_n(colors_.begin() + ptrdiff_t(before[i].positions), p.positions.size(), glm::vec4(1.0f));
      else if (coloured_) std::copy(p.colors.begin(), p.colors.end(), colors_.begin() + ptrdiff_t(before[i].positions));
      std::vector<glm::vec3>().swap(p.positions);
      std::vector<glm::vec4>().swap(p.colors);
      std::vector<glm::vec2>().swap(p.texcoords);
      std::vector<glm::vec3>().swap(p.normals);
    });
    step("parse: faces resolved");
    parallelFor(pieces.size(), opt_.threads, [&](size_t i) { objpiece::resolvePiece(pieces[i], before[i], positions_); });
    // The events in file order (serial: state, warnings, the first error); each run's corners are given
    // their place in their mesh and copied there on all cores.
    struct Copy {
      size_t piece, first, end, mesh, at;
    };
    std::vector<Copy> copies;
    step("parse: events replayed (one thread)");
    for (size_t i = 0; i < pieces.size(); ++i) replay(pieces[i], i, copies);
    for (const Copy& c : copies) {
      GrowArray<Corner>& v = builds_[c.mesh].corners;
      v.resize(std::max(v.size(), c.at + (c.end - c.first)));
    }
    std::vector<std::array<uint32_t, 3>> least(copies.size(), {kAbsent, kAbsent, kAbsent});
    step("parse: corners copied");
    parallelFor(copies.size(), opt_.threads, [&](size_t k) {
      const Copy& c = copies[k];
      const std::vector<Corner>& from = pieces[c.piece].corners;
      std::copy(from.begin() + ptrdiff_t(c.first), from.begin() + ptrdiff_t(c.end),
                builds_[c.mesh].corners.begin() + ptrdiff_t(c.at));
      for (size_t i = c.first; i < c.end; ++i)
        least[k] = {std::min(least[k][0], from[i].p), std::min(least[k][1], from[i].t), std::min(least[k][2], from[i].n)};
    });
    for (size_t k = 0; k < copies.size(); ++k)
      for (int a = 0; a < 3; ++a) builds_[copies[k].mesh].least[a] = std::min(builds_[copies[k].mesh].least[a], least[k][a]);
    step("parse: pieces freed");
    parallelFor(pieces.size(), opt_.threads, [&](size_t i) { pieces[i] = objpiece::Piece(); });  // freed on all cores
  }

  template <class Copies>
  void replay(const objpiece::Piece& p, size_t piece, Copies& copies) {
    using objpiece::EventKind;
    const size_t first = line_;
    for (const objpiece::Event& e : p.events) {
      line_ = first + e.line;
      switch (e.kind) {
        case EventKind::Faces: break;  // resolved into the kinds below
        case EventKind::Run: {
          if (mesh_ == kAbsent) mesh_ = currentMesh();
          copies.push_back({piece, e.first, e.end, mesh_, builds_[mesh_].queued});
          builds_[mesh_].queued += e.end - e.first;
          break;
        }
        case EventKind::Object: objectLine(e.text); break;
        case EventKind::Usemtl: usemtlLine(e.text); break;
        case EventKind::Mtllib: mtllibLine(e.text); break;
        case EventKind::Unknown:
          if (std::find(unknown_.begin(), unknown_.end(), e.text) == unknown_.end()) {
            unknown_.push_back(e.text);
            warn("unknown OBJ keyword '" + e.text + "' ignored");
          }
          break;
        case EventKind::Warn: warn(e.text); break;
        case EventKind::Dangling:
          if (!danglingWarned_) warn(e.text);
          danglingWarned_ = true;
          break;
        case EventKind::Error: throw error(e.text);
      }
    }
    line_ = first + p.lines;
    stats_.faces += p.faceCount;
    stats_.degenerateSkipped += p.degenerate;
    stats_.warnings += p.silentWarnings;
    pointsAndLines_ += p.pointsAndLines;
  }

  void objectLine(std::string n) {
    if (n.empty()) n = "default";
    groupsSeen_ = true;
    auto [it, added] = objectIds_.try_emplace(n, uint32_t(objectNames_.size()));
    if (added) objectNames_.push_back(n);
    object_ = it->second;
    mesh_ = kAbsent;
  }

  void usemtlLine(const std::string& name) {
    if (!mtlSeen_ && !besideMtl_.empty()) {  // no mtllib: the course's NAME.mtl convention
      mtlSeen_ = true;
      if (loadMtl(besideMtl_, mtlLabel(besideMtl_)))
        note(name_ + ": no 'mtllib' line; using '" + mtlLabel(besideMtl_) + "' beside it");
    }
    material_ = materialId(name, true);
    if (!groupsSeen_) {  // no o/g lines: each usemtl run is an object (the ray tracer's lights)
      object_ = uint32_t(objectNames_.size());
      objectNames_.push_back(materials_[material_].material.name);
    }
    mesh_ = kAbsent;
  }

  void mtllibLine(const std::string& file) {
    if (opt_.mtl) {
      if (!mtllibIgnored_)
        note(name_ + ":" + std::to_string(line_) + ": 'mtllib " + file + "' ignored; using '" + opt_.mtl->string() +
             "' as given");
      mtllibIgnored_ = true;
    } else if (!loadMtl(file, mtlLabel(file))) {
      warn("material library '" + mtlLabel(file) + "' named by 'mtllib' does not exist; its materials get default values");
    }
    mtlSeen_ = true;
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

  GrowArray<glm::vec3> positions_, normals_;
  GrowArray<glm::vec4> colors_;  // one per position once a `v` line has a colour; empty before
  GrowArray<glm::vec2> texcoords_;
  std::vector<MeshBuild> builds_;
  std::unordered_map<uint64_t, uint32_t> meshIds_;
  std::vector<std::string> objectNames_;
  std::unordered_map<std::string, uint32_t> objectIds_;
  std::vector<MtlMaterial> materials_;
  std::unordered_map<std::string, uint32_t> materialIds_;
  std::vector<std::string> mtlFiles_, unknown_;
  std::string besideMtl_;
  uint32_t object_ = kAbsent, material_ = kAbsent, mesh_ = kAbsent;
  bool groupsSeen_ = false, mtlSeen_ = false, mtllibIgnored_ = false, danglingWarned_ = false, coloured_ = false;
  size_t pointsAndLines_ = 0;
};

Scene ObjParser::finish() {
  step("weld: heap trimmed (one thread)");
  ::malloc_trim(0);  // the batches' pieces, freed, went back to the heap, not to the system
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

  // Weld: small meshes one per thread, then each large one on all threads (the same meshes either way).
  std::vector<Mesh> meshes(builds_.size());
  std::vector<WeldCounts> counts(builds_.size());
  const std::function<void(const char*)> none;
  auto weld = [&](size_t i, unsigned threads, const std::function<void(const char*)>& steps) {
    counts[i] = weldMesh(
        builds_[i].corners, positions_, normals_, texcoords_, meshes[i], opt_.creaseDeg, colors_, threads,
        [&] { builds_[i].corners.release(threads); }, steps);
    builds_[i].corners.release(threads);
  };
  const auto large = [&](size_t i) { return builds_[i].corners.size() > kLargeMesh; };
  double all = 0, done = 0;  // corners
  for (const MeshBuild& b : builds_) all += double(b.corners.size());
  auto progress = [&](double corners) {
    done += corners;
    if (opt_.weldProgress) opt_.weldProgress(all > 0 ? done / all : 1.0);
  };
  progress(0);
  step("weld: small meshes (one a thread)");
  parallelFor(builds_.size(), opt_.threads, [&](size_t i) {
    if (!large(i)) weld(i, 1, none);
  });
  for (size_t i = 0; i < builds_.size(); ++i) done += large(i) ? 0.0 : double(counts[i].triangles + counts[i].degenerate) * 3;
  progress(0);
  // The file's arrays below what the meshes left to weld use go back before each large one (at 100 M, the
  // floor's and columns' v and vt, 0.4 GB, at the statue's weld, the peak of memory).
  std::vector<std::array<uint32_t, 3>> least(builds_.size() + 1, {kAbsent, kAbsent, kAbsent});
  for (size_t i = builds_.size(); i-- > 0;)
    for (int a = 0; a < 3; ++a) least[i][a] = std::min(least[i + 1][a], large(i) ? builds_[i].least[a] : kAbsent);
  for (size_t i = 0; i < builds_.size(); ++i)
    if (large(i)) {
      step("weld: the file's arrays dropped below");
      positions_.dropBelow(least[i][0], opt_.threads);
      colors_.dropBelow(least[i][0], opt_.threads);
      texcoords_.dropBelow(least[i][1], opt_.threads);
      normals_.dropBelow(least[i][2], opt_.threads);
      const double corners = double(builds_[i].corners.size());
      try {
        weld(i, opt_.threads, opt_.step);
      } catch (const Error& e) {  // a mesh beyond the weld's limit
        throw fileError(name_, "object '" + builds_[i].name + "'", e.what());
      }
      progress(corners);
    }

  step("weld: the scene made");
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
  std::clock_t c0 = std::clock();
  parser.run(source);
  st.parseSeconds = since(t0);
  st.parseCpuSeconds = cpuSince(c0);
  t0 = Clock::now();
  c0 = std::clock();
  Scene scene = parser.finish();
  st.weldSeconds = since(t0);
  st.weldCpuSeconds = cpuSince(c0);
  return scene;
}

Scene loadObj(const std::filesystem::path& file, const ObjOptions& options, ObjStats* stats) {
  auto src = openSource(file, options.threads);
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
