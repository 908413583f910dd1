#pragma once
// The OBJ text parse in fixed pieces, for obj.cpp to run on all cores and stitch. A piece is parsed alone
// (parsePiece); once the counts before it are known its faces are resolved and triangulated
// (resolvePiece); obj.cpp then replays its events in order. What crosses pieces (o/g/usemtl state, MTLs,
// warnings that are shown once, the first error) is decided only in that replay, so the result does not
// depend on where the pieces end. Internal to the OBJ reader.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "scene/weld.hpp"

namespace rtr::objpiece {

constexpr int64_t kNoIndex = INT64_MIN;  // a corner without that attribute

enum class EventKind : uint8_t {
  Faces,     // raw faces [first, end) (parsePiece only; resolvePiece turns them into the kinds below)
  Object,    // o / g, text: the name
  Usemtl,    // text: the material name
  Mtllib,    // text: the file name
  Unknown,   // an unknown keyword (first in the piece), text: it
  Warn,      // text: the message
  Dangling,  // the piece's first face with an index pointing nowhere, text: the message
  Run,       // triangle corners [first, end) for the current mesh (one face of 3+ corners at least)
  Error,     // text: the message; nothing after it in the piece was parsed
};

struct Event {
  EventKind kind;
  uint64_t line;  // counted from the piece's first line (1)
  std::string text;
  size_t first = 0, end = 0;
};

struct RawFace {   // 32 bytes: a piece is at most one batch of text, so its counts fit 32 bits
  uint32_t line;   // as Event::line
  uint32_t first;  // into Piece::raw, 3 per corner (v, vt, vn)
  uint32_t corners;
  uint32_t positions, texcoords, normals;  // the piece's records before the line
  bool broken;                             // its line has an error after these corners
};

struct Piece {
  std::string_view text;   // whole lines
  bool fileStart = false;  // holds the file's first line (a UTF-8 byte order mark is skipped)
  // parsePiece
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec4> colors;  // empty, or one per position once a `v` line of the piece had a colour
  std::vector<glm::vec2> texcoords;
  std::vector<int64_t> raw;
  std::vector<RawFace> faces;
  std::vector<Event> events;
  uint64_t lines = 0;
  size_t pointsAndLines = 0;
  // resolvePiece
  std::vector<Corner> corners;
  size_t faceCount = 0, degenerate = 0;
  size_t silentWarnings = 0;  // warnings past the first few of the piece: counted, never shown
};

// Where a piece may end: just after the first line end at or past `at` that does not continue the line
// (`\` before it); text.size() when none.
size_t pieceEnd(std::string_view text, size_t at);

// Just after the last line end of `text` that does not continue the line; 0 when none.
size_t lastLineEnd(std::string_view text);

void parsePiece(Piece& p);

// `positions` etc.: the records of the whole file so far, this piece's included; `before`: this piece's
// first index into them.
struct Counts {
  size_t positions = 0, texcoords = 0, normals = 0;
};
void resolvePiece(Piece& p, const Counts& before, std::span<const glm::vec3> positions);

}  // namespace rtr::objpiece
