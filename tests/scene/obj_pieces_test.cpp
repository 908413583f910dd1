// The OBJ parse on all cores: text split into pieces at line ends, stitched so that the scene, the
// statistics, every warning and note, and the error (the first in file order, with its line) are those
// of one piece on one thread, wherever the pieces end (tiny pieces put a boundary at every line).
#include <filesystem>
#include <map>
#include <random>

#include <gtest/gtest.h>
#include <zstd.h>

#include "core/error.hpp"
#include "scene/grow_array.hpp"
#include "scene/obj.hpp"
#include "scene_compare.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using namespace rtr;

namespace {

struct Outcome {
  Scene scene;
  ObjStats stats;
  std::vector<std::string> messages;  // warnings and notes, in order
  std::string error;
};

ObjOptions options(Outcome& r, unsigned threads, size_t pieceBytes) {
  ObjOptions opt;
  opt.threads = threads;
  opt.pieceBytes = pieceBytes;
  opt.warn = [&r](const std::string& w) { r.messages.push_back("warning: " + w); };
  opt.note = [&r](const std::string& n) { r.messages.push_back("note: " + n); };
  return opt;
}

// `bytes`: OBJ text, or zstd frames of it.
Outcome parseBytes(const std::string& bytes, const std::map<std::string, std::string>& mtls, unsigned threads, size_t pieceBytes,
                   bool zstd) {
  Outcome r;
  const ObjOptions opt = options(r, threads, pieceBytes);
  auto src = memorySource(bytes, "t.obj", zstd, threads);
  auto readMtl = [&](const std::string& n) -> std::optional<std::string> {
    auto it = mtls.find(n);
    if (it == mtls.end()) return std::nullopt;
    return it->second;
  };
  try {
    r.scene = parseObj(*src, "t.obj", readMtl, opt, &r.stats, mtls.count("t.mtl") ? "t.mtl" : "");
  } catch (const Error& e) { r.error = e.what(); }
  return r;
}

Outcome parseText(const std::string& obj, const std::map<std::string, std::string>& mtls, unsigned threads, size_t pieceBytes,
                  bool zstd = false) {
  std::string bytes = obj;
  if (zstd) {
    bytes.resize(ZSTD_compressBound(obj.size()));
    bytes.resize(ZSTD_compress(bytes.data(), bytes.size(), obj.data(), obj.size(), 1));
  }
  return parseBytes(bytes, mtls, threads, pieceBytes, zstd);
}

Outcome parseFile(const fs::path& file, unsigned threads, size_t pieceBytes) {
  Outcome r;
  try {
    r.scene = loadObj(file, options(r, threads, pieceBytes), &r.stats);
  } catch (const Error& e) { r.error = e.what(); }
  return r;
}

void expectSame(const Outcome& a, const Outcome& b) {
  EXPECT_EQ(a.error, b.error);
  EXPECT_EQ(a.messages, b.messages);
  if (!a.error.empty() || !b.error.empty()) return;  // the counts are of what was read before it
  EXPECT_EQ(a.stats.textBytes, b.stats.textBytes);
  EXPECT_EQ(a.stats.positions, b.stats.positions);
  EXPECT_EQ(a.stats.normals, b.stats.normals);
  EXPECT_EQ(a.stats.texcoords, b.stats.texcoords);
  EXPECT_EQ(a.stats.faces, b.stats.faces);
  EXPECT_EQ(a.stats.triangles, b.stats.triangles);
  EXPECT_EQ(a.stats.degenerateSkipped, b.stats.degenerateSkipped);
  EXPECT_EQ(a.stats.verticesAfterWeld, b.stats.verticesAfterWeld);
  EXPECT_EQ(a.stats.warnings, b.stats.warnings);
  rtr::test::expectSameScene(a.scene, b.scene);
}

// One piece on one thread is the reference; then pieces ending at (nearly) every line, on 1 and 3 threads.
constexpr size_t kPieceSizes[] = {1, 2, 3, 7, 16, 61, 500};

void expectStitchedAsOne(const std::string& obj, const std::map<std::string, std::string>& mtls = {}) {
  const Outcome one = parseText(obj, mtls, 1, size_t(1) << 30);
  for (size_t piece : kPieceSizes)
    for (unsigned threads : {1u, 3u}) {
      SCOPED_TRACE("piece " + std::to_string(piece) + " bytes, " + std::to_string(threads) + " threads");
      expectSame(one, parseText(obj, mtls, threads, piece));
    }
}

// OBJ text with everything whose meaning depends on lines before it: relative indices, o/g/usemtl state,
// an mtllib in the middle, vertex colours that start late, continued lines, CRLF, dangling indices and
// self-crossing polygons (more warnings than are shown).
std::string generated(unsigned seed, int lines = 1500) {
  std::mt19937 rng(seed);
  auto pick = [&](int n) { return int(rng() % unsigned(n)); };
  std::string s = "\xEF\xBB\xBF# generated\n";
  int v = 0, vt = 0, vn = 0;
  for (int line = 0; line < lines; ++line) {
    const int k = pick(40);
    const std::string eol = pick(5) == 0 ? "\r\n" : "\n";
    if (k < 10 || v < 4) {
      ++v;
      s += "v " + std::to_string(pick(100) * 0.25) + " " + std::to_string(pick(100) * 0.5) +
           (pick(8) ? " " : " \\" + eol + "  ") + std::to_string(pick(50));
      if (v > 150 && pick(3) == 0) s += " 0.5 0.25 1";
      s += eol;
    } else if (k < 13) {
      ++vt, s += "vt 0." + std::to_string(pick(10)) + " 0." + std::to_string(pick(10)) + eol;
    } else if (k < 15) {
      ++vn, s += "vn 0 " + std::to_string(pick(2)) + " 1" + eol;
    } else if (k < 30) {
      const int n = pick(6) == 0 ? 5 : pick(4) == 0 ? 4 : pick(30) == 0 ? 2 : 3;
      s += "f";
      for (int c = 0; c < n; ++c) {
        const int p = 1 + pick(v);
        s += " " + (pick(2) ? std::to_string(p) : std::to_string(p - v - 1));  // absolute or relative
        const int form = pick(4);
        if (form == 1 && vt) s += "/" + std::to_string(pick(9) == 0 ? vt + 3 : -1 - pick(vt));
        if (form == 2 && vn) s += "//" + std::to_string(1 + pick(vn + 1));
        if (c == 1 && pick(25) == 0) s += " \\" + eol;
      }
      s += eol;
    } else if (k < 32) {
      s += (pick(2) ? "o obj" : "g grp") + std::to_string(pick(4)) + eol;
    } else if (k < 35) {
      s += "usemtl m" + std::to_string(pick(5)) + eol;
    } else if (k == 35) {
      s += pick(2) ? "s off" + eol : "s " + std::to_string(pick(4)) + eol;
    } else if (k == 36) {
      s += line > 700 ? "mtllib lib.mtl" + eol : "# comment \\" + eol + eol;  // the comment takes the empty line
    } else if (k == 37) {
      s += "l 1 2" + eol + "   " + eol;
    } else if (k == 38) {
      s += "bevel on" + eol;
    } else if (pick(2)) {
      s += "\t" + eol;
    } else {  // a bow tie: crosses itself
      v += 5,
          s += "v 4 1 0" + eol + "v 4 4 0" + eol + "v 1 3 0" + eol + "v 0 3 0" + eol + "v 2 4 0" + eol + "f -5 -4 -3 -2 -1" + eol;
    }
  }
  return s + "f 1 2 3 \\";  // no line end at the end, and a continuation into nothing
}

const std::map<std::string, std::string> kMtls = {{"lib.mtl", "newmtl m1\nKd 1 0 0\nnewmtl m3\nKe 1 1 1\nbogus 1\n"},
                                                  {"t.mtl", "newmtl m0\nKd 0 1 0\n"}};

}  // namespace

TEST(ObjPieces, GeneratedTextStitchesAsOnePiece) {
  for (unsigned seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const std::string obj = generated(seed);
    const Outcome one = parseText(obj, kMtls, 1, size_t(1) << 30);
    ASSERT_EQ(one.error, "");
    ASSERT_GT(one.scene.meshes.size(), 5u);  // the state crossed pieces
    ASSERT_GT(one.stats.warnings, 10u);      // the warning cap crossed pieces
    ASSERT_FALSE(one.scene.meshes[0].colors.empty());
    expectStitchedAsOne(obj, kMtls);
  }
}

// A zstd stream is read in batches of about its compressed size (the text is larger): the pieces of one
// batch are parsed while the next is read, and the stitch carries across batches as across pieces.
TEST(ObjPieces, BatchesStitchAsOne) {
  const std::string obj = generated(4, 12000);
  const Outcome one = parseText(obj, kMtls, 1, size_t(1) << 30);
  ASSERT_EQ(one.error, "");
  const Outcome zstd = parseText(obj, kMtls, 1, size_t(1) << 30, true);
  ASSERT_GT(obj.size(), 3 * std::max<size_t>(65536, ZSTD_compressBound(obj.size()) / 4)) << "several batches";
  expectSame(one, zstd);
  expectSame(one, parseText(obj, kMtls, 3, 700, true));
  const size_t half = obj.find('\n', obj.size() / 2) + 1;
  const std::string bad = obj.substr(0, half) + "\nf 1 2 x\n" + obj.substr(half) + "\nf 99999999 1 2\n";
  const Outcome badOne = parseText(bad, kMtls, 1, size_t(1) << 30);
  EXPECT_NE(badOne.error.find(": face corner is not an index"), std::string::npos) << badOne.error;
  expectSame(badOne, parseText(bad, kMtls, 3, 700, true));
}

// Small cases after the ones other readers' test suites are known for.
// zstd frames that say their size are decoded on all cores as they fit the batch; a frame larger than the
// batch, one that does not say its size and a skippable frame are read in between; a damaged frame names
// its first byte.
TEST(ObjPieces, ZstdFramesReadAsOneStream) {
  const std::string obj = generated(5, 40000);
  const Outcome one = parseText(obj, kMtls, 1, size_t(1) << 30);
  ASSERT_EQ(one.error, "");
  ZSTD_CCtx* z = ZSTD_createCCtx();
  ZSTD_CCtx_setParameter(z, ZSTD_c_checksumFlag, 1);
  auto frame = [&](std::string_view text, bool sized) {
    std::string out(ZSTD_compressBound(text.size()) + 64, '\0');
    ZSTD_CCtx_reset(z, ZSTD_reset_session_only);
    if (sized) return out.substr(0, ZSTD_compress2(z, out.data(), out.size(), text.data(), text.size()));
    ZSTD_inBuffer in{text.data(), text.size(), 0};  // streamed: the frame does not record its size
    ZSTD_outBuffer o{out.data(), out.size(), 0};
    while (ZSTD_compressStream2(z, &o, &in, ZSTD_e_end) != 0) {}
    return out.substr(0, o.pos);
  };
  std::string bytes;
  std::vector<size_t> starts;  // where each frame begins
  const size_t cuts[] = {0, 1, 100, 5000, 9000, 300000, 300001, obj.size() / 2, obj.size() / 2 + 70000, obj.size()};
  for (size_t i = 0; i + 1 < std::size(cuts); ++i) {
    starts.push_back(bytes.size());
    bytes += frame(std::string_view(obj).substr(cuts[i], cuts[i + 1] - cuts[i]), i != 6);
    if (i == 2)
      bytes += std::string(
          "\x50\x2A\x4D\x18\x03\x00\x00\x00"
          "abc",
          11);  // skippable, 3 bytes
  }
  ZSTD_freeCCtx(z);
  for (unsigned threads : {1u, 3u}) {
    SCOPED_TRACE(threads);
    expectSame(one, parseBytes(bytes, kMtls, threads, size_t(1) << 30, true));
  }
  // A damaged checksum: the frame decoded whole names its first byte; damage in its blocks is found by
  // the stream, which names a byte inside the frame.
  for (const size_t at : {starts[6] - 1, starts[5] + 40}) {
    std::string bad = bytes;
    bad[at] ^= 0x20;
    const std::string error = parseBytes(bad, kMtls, 3, size_t(1) << 30, true).error;
    const size_t named = error.rfind("t.obj: byte ", 0) == 0 ? std::stoul(error.substr(12)) : 0;
    EXPECT_NE(error.find("corrupt zstd stream"), std::string::npos) << error;
    if (at == starts[6] - 1) { EXPECT_EQ(named, starts[5]) << error; }
    EXPECT_TRUE(named >= starts[5] && named <= starts[6]) << error;
  }
}

TEST(ObjPieces, CornerCasesStitchAsOnePiece) {
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const char* cases[] = {
      "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf -3 -2 -1\r\nv 0 0 1\r\nf -4 -3 -1\r\nf 1 -1 2",  // CRLF, relative, no final line end
      "g a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\ng b\nf 1 2 3\ng a\nf 3 2 1\ng\nf 1 3 2\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m0\nf 1 2 3\nusemtl m1\nf 1 2 3\nusemtl m0\nf 1 3 2\n",  // NAME.mtl at usemtl
      "mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nmtllib lib.mtl\nusemtl m1\nf 1 2 3\nmtllib lib.mtl\n",
      "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 0 0 1\nv 1 1 0\nf 1 2 3 4\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/5/1 3/1/9\nf 1/1 2/1 3/-4\nf 1//1 2//1 3//1\n",
      "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 1 0.5 0\nv 0 2 0\nf 1 2 3 4 5\nv 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nf -4 -3 -2 -1\n",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 1 1 1\nf 1 2 3\np 1\nl 1 2\nfoo 1\nfoo 2\nbar\n",
      "v 0 0 \\\n 0\nv 1 \\\r\n0 0\nv 0 1 0\nf 1 \\\n2 \\\n\\\n 3\n# a comment \\\nf 1 2 3\n",
      "\n\n   \n\t\nv 0 0 0\n\nv 1 0 0\nv 0 1 0\n\n\nf 1 2 3\n\n",
  };
  for (const char* c : cases) {
    SCOPED_TRACE(c);
    expectStitchedAsOne(c, kMtls);
  }
  std::string crossing = "v 4 1 0\nv 4 4 0\nv 1 3 0\nv 0 3 0\nv 2 4 0\n";  // more crossing polygons than warnings shown
  for (int i = 0; i < 25; ++i) crossing += "f 1 2 3 4 5\n";
  expectStitchedAsOne(crossing);
}

// The first error in file order, with its line, is the one reported, and the warnings before it are
// shown, wherever the pieces end.
TEST(ObjPieces, TheFirstErrorWins) {
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const std::string lateBad = "\nf 1 2 3\nv 1 2 x\nf 1 2 99\n";
  const std::string cases[] = {
      tri + "f 1 2 99\n" + lateBad,              // out of range (known only with the counts before) before a syntax error
      tri + "f 1 2 x\n" + "f 1 2 99\n",          // syntax error before out of range
      tri + "f 99 x\n",                          // in one line: the index before the bad corner is checked first
      tri + "f 1/7 2/x 3\n" + lateBad,           // a dangling texcoord warning, then the error on that line
      tri + "f 1 2 3 -4\n" + lateBad,            // relative index before the first vertex
      tri + "f 0 1 2\n" + lateBad,               // index 0
      tri + "f 1//x 2 3\n" + lateBad,            // normal index
      tri + "f 1 2 3a\n" + lateBad,              // junk after a corner
      tri + "vt 1 nan\n" + lateBad,              // not finite
      tri + "vn 1 2\n" + lateBad,                // too few numbers
      tri + "v 1e13 0 0\n" + lateBad,            // beyond the coordinate limit
      tri + "foo\nf 1 2 3\nmtllib\n" + lateBad,  // a warning, then an mtllib naming nothing
      tri + "f 1 \\\n 2 \\\n 99\nf 1 2 x\n",     // on a continued line: the line it starts on
      "# nothing\n\nl 1 2\n",                    // nothing to draw
  };
  for (const std::string& c : cases) {
    SCOPED_TRACE(c);
    const Outcome one = parseText(c, kMtls, 1, size_t(1) << 30);
    EXPECT_NE(one.error, "") << "every case is refused";
    expectStitchedAsOne(c, kMtls);
  }
  EXPECT_NE(parseText(tri + "f 1 2 99\n" + lateBad, {}, 1, 1 << 30).error.find("t.obj:4:"), std::string::npos);
  EXPECT_NE(parseText(tri + "f 1 \\\n 2 \\\n 99\nf 1 2 x\n", {}, 1, 1 << 30).error.find("t.obj:4:"), std::string::npos);
}

// Files nobody here wrote, and the project's own temple.
TEST(ObjPieces, FilesStitchAsOnePiece) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator("/usr/share/assimp/models/OBJ"))
    if (e.path().extension() == ".obj") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_GT(files.size(), 15u);
  files.push_back(test::sourceDir() / "assets-src/temple/temple.obj.zst");
  for (const fs::path& f : files) {
    SCOPED_TRACE(f.string());
    const Outcome one = parseFile(f, 1, size_t(1) << 30);
    for (size_t piece : {size_t(1), size_t(13), size_t(4096)}) {
      SCOPED_TRACE("piece " + std::to_string(piece));
      expectSame(one, parseFile(f, 3, piece));
    }
  }
}

// Vertex colours that begin in a later batch: the positions of the batches before them are white, as in
// one batch.
TEST(ObjPieces, ColoursBeginningInALaterBatch) {
  std::string obj;
  for (int i = 0; i < 30000; ++i) obj += "v " + std::to_string(i % 97) + " " + std::to_string(i / 97) + " 0\n";
  obj += "v 0 0 1 1 0 0\nv 1 0 1 0 1 0\nv 0 1 1 0 0 1\nf 1 2 98\nf -3 -2 -1\n";
  const Outcome one = parseText(obj, {}, 1, size_t(1) << 30);
  ASSERT_EQ(one.error, "");
  ASSERT_EQ(one.scene.meshes.size(), 1u);
  const Mesh& m = one.scene.meshes[0];
  ASSERT_EQ(m.colors.size(), 6u);
  for (size_t v = 0; v < 6; ++v) EXPECT_EQ(m.colors[v] == glm::vec4(1.0f), m.positions[v].z == 0.0f) << v;
  const Outcome batches = parseText(obj, {}, 3, 4096, true);
  ASSERT_GT(obj.size(), 3 * size_t(65536)) << "several batches";
  expectSame(one, batches);
}

// The arrays the OBJ reader grows batch by batch keep what they hold when they grow, small or large (a large
// block is moved by the kernel, not copied).
TEST(ObjPieces, GrowArrayKeepsWhatItHolds) {
  GrowArray<uint32_t> a;
  size_t n = 0;
  for (size_t step : {size_t(1), size_t(7), size_t(1000), size_t(300000), size_t(5000000), size_t(20000000)}) {
    a.resize(n + step);
    for (size_t i = n; i < n + step; ++i) a[i] = uint32_t(i * 2654435761u);
    n += step;
    bool same = true;
    for (size_t i = 0; i < n; ++i) same = same && a[i] == uint32_t(i * 2654435761u);
    EXPECT_TRUE(same) << n;
  }
  GrowArray<uint32_t> b = std::move(a);
  EXPECT_EQ(b.size(), n);
  EXPECT_TRUE(a.empty());
  EXPECT_EQ(b[n - 1], uint32_t((n - 1) * 2654435761u));
  b.release();
  EXPECT_TRUE(b.empty());
}
