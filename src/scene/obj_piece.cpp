#include "scene/obj_piece.hpp"

#include <algorithm>
#include <array>
#include <cstring>

#include "core/bounds.hpp"
#include "scene/text.hpp"
#include "scene/triangulate.hpp"

namespace rtr::objpiece {
namespace {

constexpr size_t kMaxName = 32767;
constexpr size_t kShownWarnings = 10;  // as obj.cpp: more in one piece are only counted

struct Stop {  // a line's error
  std::string what;
};

// The line without its continuation mark, or npos when it does not continue.
size_t continuedAt(std::string_view l) {
  size_t e = l.size();
  if (e && l[e - 1] == '\r') --e;
  return e && l[e - 1] == '\\' ? e - 1 : std::string_view::npos;
}

std::string checkedName(std::string_view what, std::string_view s) {
  s = text::trim(s);
  if (s.size() > kMaxName) throw Stop{std::string(what) + " longer than " + std::to_string(kMaxName) + " bytes"};
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
        if (i < required) throw Stop{std::string("'") + key + "' needs " + std::to_string(required) + " numbers"};
        i = N;
        break;
      case text::NumResult::NotFinite: throw Stop{std::string("'") + key + "' coordinate is NaN or infinite"};
      default: throw Stop{std::string("'") + key + "' coordinate is not a number"};
    }
  }
  out.push_back(v);
}

// `v x y z`, or `v x y z r g b` (vertex colours, as other readers take them; a lone 4th number is w).
// What follows the third number is read only as colour: anything else there is ignored.
void vertex(Piece& p, std::string_view rest) {
  float f[6] = {};
  int n = 0;
  for (; n < 6; ++n) {
    const text::NumResult r = text::nextFloat(rest, f[n]);
    if (r == text::NumResult::Ok) continue;
    if (n >= 3) break;
    if (r == text::NumResult::Missing) throw Stop{"'v' needs 3 numbers"};
    if (r == text::NumResult::NotFinite) throw Stop{"'v' coordinate is NaN or infinite"};
    throw Stop{"'v' coordinate is not a number"};
  }
  if (!coordinateOk(glm::vec3(f[0], f[1], f[2])))  // the limit every reader applies
    throw Stop{"vertex coordinate beyond ±1e12 (the coordinate limit, docs/files-and-cli.md)"};
  p.positions.push_back({f[0], f[1], f[2]});
  const bool coloured = n == 6;
  if (coloured && p.colors.size() < p.positions.size() - 1) p.colors.assign(p.positions.size() - 1, glm::vec4(1.0f));
  if (coloured || !p.colors.empty()) p.colors.push_back(coloured ? glm::vec4(f[3], f[4], f[5], 1.0f) : glm::vec4(1.0f));
}

// Parses one signed index; returns false at the end of the token.
bool parseIndex(const char*& s, const char* e, int64_t& v) {
  bool neg = false;
  if (s < e && *s == '-') {
    neg = true;
    ++s;
  }
  const char* b = s;
  int64_t x = 0;
  while (s < e && unsigned(*s - '0') < 10u) {
    x = x * 10 + (*s - '0');
    if (x > (int64_t(1) << 40)) return false;
    ++s;
  }
  if (s == b) return false;
  v = neg ? -x : x;
  return true;
}

// The corners as written; indices are resolved by resolvePiece, which knows the counts before the piece.
void face(Piece& p, std::string_view rest, uint64_t line) {
  if (p.events.empty() || p.events.back().kind != EventKind::Faces)
    p.events.push_back({EventKind::Faces, line, {}, p.faces.size(), p.faces.size()});
  RawFace f{uint32_t(line),
            uint32_t(p.raw.size()),
            0,
            uint32_t(p.positions.size()),
            uint32_t(p.texcoords.size()),
            uint32_t(p.normals.size()),
            false};
  auto stop = [&](const char* what) {  // the corners before the fault still get resolved (their errors come first)
    f.broken = true;
    p.faces.push_back(f);
    p.events.back().end = p.faces.size();
    throw Stop{what};
  };
  const char* s = rest.data();
  const char* e = s + rest.size();
  for (;;) {
    while (s < e && text::isSpace(*s)) ++s;
    if (s == e) break;
    int64_t v = 0, t = kNoIndex, n = kNoIndex;
    if (!parseIndex(s, e, v)) stop("face corner is not an index (expected v, v/vt, v//vn or v/vt/vn)");
    if (s < e && *s == '/') {
      ++s;
      if (s < e && *s != '/' && !parseIndex(s, e, t)) {
        p.raw.insert(p.raw.end(), {v, kNoIndex, kNoIndex});  // its position is resolved before this error
        ++f.corners;
        stop("face texture coordinate index is not a number");
      }
      if (s < e && *s == '/') {
        ++s;
        if (!parseIndex(s, e, n)) {
          p.raw.insert(p.raw.end(), {v, t, kNoIndex});
          ++f.corners;
          stop("face normal index is not a number");
        }
      }
    }
    p.raw.insert(p.raw.end(), {v, t, n});
    ++f.corners;
    if (s < e && !text::isSpace(*s)) stop("unexpected character in face corner");
  }
  p.faces.push_back(f);
  p.events.back().end = p.faces.size();
}

void onLine(Piece& p, std::string_view l, uint64_t line) {
  if (p.fileStart && line == 1 && l.substr(0, 3) == "\xEF\xBB\xBF") l.remove_prefix(3);  // UTF-8 byte order mark
  size_t i = 0;
  while (i < l.size() && text::isSpace(l[i])) ++i;
  if (i == l.size()) return;
  const char c0 = l[i];
  const char c1 = i + 1 < l.size() ? l[i + 1] : '\0';
  const bool sep1 = c1 == '\0' || text::isSpace(c1);
  if (c0 == 'v' && sep1) return vertex(p, l.substr(i + 1));
  if (c0 == 'f' && sep1) return face(p, l.substr(i + 1), line);
  const bool sep2 = i + 2 == l.size() || (i + 2 < l.size() && text::isSpace(l[i + 2]));
  if (c0 == 'v' && c1 == 'n' && sep2) return vec<3>(l.substr(i + 2), p.normals, "vn", 3);
  if (c0 == 'v' && c1 == 't' && sep2) return vec<2>(l.substr(i + 2), p.texcoords, "vt", 1);
  if (c0 == '#') return;
  std::string_view rest = l.substr(i);
  const std::string_view key = text::nextToken(rest);
  if (key == "o" || key == "g") {
    p.events.push_back({EventKind::Object, line, checkedName("object name", rest)});
  } else if (key == "usemtl") {
    p.events.push_back({EventKind::Usemtl, line, checkedName("material name", rest)});
  } else if (key == "mtllib") {
    std::string file = checkedName("mtllib file name", rest);
    if (file.empty()) throw Stop{"'mtllib' names no file"};
    p.events.push_back({EventKind::Mtllib, line, std::move(file)});
  } else if (key == "l" || key == "p") {
    ++p.pointsAndLines;  // nothing to draw for triangle meshes; one note at the end
  } else if (key == "s" || key == "cstype" || key == "vp") {
    // smoothing groups and free-form data carry nothing for triangle meshes
  } else {
    const std::string k(key.substr(0, 64));
    const bool seen = std::any_of(p.events.begin(), p.events.end(),
                                  [&](const Event& e) { return e.kind == EventKind::Unknown && e.text == k; });
    if (!seen) p.events.push_back({EventKind::Unknown, line, k});
  }
}

// A texcoord or normal index that points nowhere: kAbsent (the face loses that attribute).
uint32_t resolveLenient(int64_t idx, size_t count, const char* what, bool& dropped, bool& warned, uint64_t line,
                        std::vector<Event>& out) {
  const int64_t r = idx > 0 ? idx - 1 : int64_t(count) + idx;
  if (idx != 0 && r >= 0 && r < int64_t(count)) return uint32_t(r);
  if (!dropped && !warned) {
    warned = true;
    out.push_back({EventKind::Dangling, line,
                   std::string("face ") + what + " index " + std::to_string(idx) + " points nowhere (" + std::to_string(count) +
                       " " + what + "s defined so far): the face's " + what + "s are dropped" +
                       (std::string(what) == "normal" ? " and computed" : "") + " (so for every such face; no more warnings)"});
  }
  dropped = true;
  return kAbsent;
}

// Empty when it resolves; else the error.
std::string resolve(int64_t idx, size_t count, const char* what, uint32_t& out) {
  if (idx == 0) return std::string("face ") + what + " index 0 is invalid (OBJ indices start at 1)";
  const int64_t r = idx > 0 ? idx - 1 : int64_t(count) + idx;
  if (r < 0 || r >= int64_t(count))
    return std::string("face ") + what + " index " + std::to_string(idx) + " out of range (" + std::to_string(count) + " " +
           what + "s defined so far)";
  out = uint32_t(r);
  return {};
}

}  // namespace

size_t pieceEnd(std::string_view text, size_t at) {
  while (at < text.size()) {
    const void* nl = std::memchr(text.data() + at, '\n', text.size() - at);
    if (!nl) return text.size();
    const size_t end = size_t(static_cast<const char*>(nl) - text.data());
    size_t b = end;  // the line's start, to see whether it continues
    while (b > 0 && text[b - 1] != '\n') --b;
    if (continuedAt(text.substr(b, end - b)) == std::string_view::npos) return end + 1;
    at = end + 1;
  }
  return text.size();
}

size_t lastLineEnd(std::string_view text) {
  for (size_t end = text.rfind('\n'); end != std::string_view::npos && end > 0; end = text.rfind('\n', end - 1)) {
    const size_t b = text.rfind('\n', end - 1);
    const size_t start = b == std::string_view::npos ? 0 : b + 1;
    if (continuedAt(text.substr(start, end - start)) == std::string_view::npos) return end + 1;
  }
  return !text.empty() && text[0] == '\n' ? 1 : 0;
}

void parsePiece(Piece& p) {
  const std::string_view t = p.text;
  std::string joined;  // a line continued with `\`: its parts, a space between
  size_t at = 0;
  while (at < t.size()) {
    const uint64_t line = p.lines + 1;
    auto next = [&] {
      const void* nl = std::memchr(t.data() + at, '\n', t.size() - at);
      const size_t end = nl ? size_t(static_cast<const char*>(nl) - t.data()) : t.size();
      const std::string_view l = t.substr(at, end - at);
      at = end + 1;
      ++p.lines;
      return l;
    };
    std::string_view l = next();
    if (size_t c = continuedAt(l); c != std::string_view::npos) {
      joined.assign(l.substr(0, c));
      while (c != std::string_view::npos && at < t.size()) {
        const std::string_view more = next();
        c = continuedAt(more);
        joined += ' ';
        joined += more.substr(0, c == std::string_view::npos ? more.size() : c);
      }
      l = joined;
    }
    try {
      onLine(p, l, line);
    } catch (const Stop& s) {
      p.events.push_back({EventKind::Error, line, s.what});
      return;
    }
  }
}

void resolvePiece(Piece& p, const Counts& before, std::span<const glm::vec3> positions) {
  std::vector<Event> out;
  out.reserve(p.events.size());
  std::vector<Corner> poly;
  std::vector<glm::vec3> polyPos;
  std::vector<std::array<uint32_t, 3>> tris;
  // Room for every corner at once (a bound: a polygon of n corners gives n - 2 triangles at most): grown
  // by doubling, the corners were copied and their pages made again about twice over, while 15 other
  // threads did the same.
  size_t bound = 0;
  for (const RawFace& f : p.faces) bound += f.corners >= 3 ? (size_t(f.corners) - 2) * 3 : 0;
  p.corners.reserve(bound);
  bool warnedDangling = false;
  size_t warnings = 0;
  for (Event& e : p.events) {
    if (e.kind != EventKind::Faces) {
      out.push_back(std::move(e));
      continue;
    }
    for (size_t fi = e.first; fi < e.end; ++fi) {
      const RawFace& f = p.faces[fi];
      const size_t np = before.positions + f.positions, nt = before.texcoords + f.texcoords, nn = before.normals + f.normals;
      poly.clear();
      bool dropT = false, dropN = false;
      for (uint32_t k = 0; k < f.corners; ++k) {
        const int64_t* r = &p.raw[f.first + 3 * size_t(k)];
        Corner c{kAbsent, kAbsent, kAbsent};
        if (std::string err = resolve(r[0], np, "position", c.p); !err.empty()) {
          out.push_back({EventKind::Error, f.line, std::move(err)});
          p.events = std::move(out);
          return;
        }
        if (r[1] != kNoIndex) c.t = resolveLenient(r[1], nt, "texcoord", dropT, warnedDangling, f.line, out);
        if (r[2] != kNoIndex) c.n = resolveLenient(r[2], nn, "normal", dropN, warnedDangling, f.line, out);
        poly.push_back(c);
      }
      if (f.broken) break;  // its error is the next event
      for (Corner& c : poly) {
        if (dropT) c.t = kAbsent;
        if (dropN) c.n = kAbsent;
      }
      ++p.faceCount;
      if (poly.size() < 3) {
        ++p.degenerate;
        continue;
      }
      tris.clear();
      if (poly.size() == 3) {
        tris.push_back({0, 1, 2});
      } else {
        polyPos.clear();
        for (const Corner& c : poly) polyPos.push_back(positions[c.p]);
        if (!triangulatePolygon(polyPos, tris)) {
          if (warnings++ < kShownWarnings)
            out.push_back({EventKind::Warn, f.line,
                           "polygon of " + std::to_string(poly.size()) + " corners crosses itself; part of it fan-triangulated"});
          else ++p.silentWarnings;
        }
      }
      if (out.empty() || out.back().kind != EventKind::Run)
        out.push_back({EventKind::Run, f.line, {}, p.corners.size(), p.corners.size()});
      for (const auto& t : tris) p.corners.insert(p.corners.end(), {poly[t[0]], poly[t[1]], poly[t[2]]});
      out.back().end = p.corners.size();
    }
  }
  p.events = std::move(out);
  std::vector<int64_t>().swap(p.raw);
  std::vector<RawFace>().swap(p.faces);
}

}  // namespace rtr::objpiece
