#include "scene/weld.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <initializer_list>
#include <memory>
#include <numeric>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/error.hpp"
#include "core/parallel.hpp"
#include "scene/grow_array.hpp"

namespace rtr {
namespace {

inline uint64_t mix(uint64_t h) {
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ull;
  h ^= h >> 33;
  return h;
}

// Grid for the tolerance weld: cells much larger than the tolerance, so a vertex usually has its
// neighbours in its own cell and only looks next door when it lies within the tolerance of a face.
constexpr float kCellScale = 1024.0f;

inline int64_t cellOf(float x) {
  double c = std::floor(double(x) * kCellScale);
  if (c > 1e15) c = 1e15;  // huge coordinates share a cell; values are compared exactly anyway
  if (c < -1e15) c = -1e15;
  return int64_t(c);
}

inline uint64_t cellHash(int64_t x, int64_t y, int64_t z) {
  return mix(uint64_t(x) * 0x9E3779B97F4A7C15ull ^ mix(uint64_t(y) + 0x632BE59BD9B4E019ull) ^ (uint64_t(z) << 1));
}

struct Vertex {  // its colour, when the file has colours, is held apart: most files have none
  glm::vec3 p, n;
  glm::vec2 t;
};

inline bool near(const Vertex& a, const Vertex& b) {
  auto c = [](float x, float y) { return std::fabs(x - y) <= kWeldTolerance; };
  return c(a.p.x, b.p.x) && c(a.p.y, b.p.y) && c(a.p.z, b.p.z) && c(a.n.x, b.n.x) && c(a.n.y, b.n.y) && c(a.n.z, b.n.z) &&
         c(a.t.x, b.t.x) && c(a.t.y, b.t.y);
}

// The cells a vertex looks in for its neighbours: its own, and the next one along an axis where it lies
// within the tolerance of that face.
struct Around {
  int64_t cell[3], lo[3], hi[3];
  explicit Around(const glm::vec3& p) {
    const float edge = kWeldTolerance * kCellScale;
    for (int d = 0; d < 3; ++d) {
      cell[d] = cellOf(p[d]);
      const float f = p[d] * kCellScale - float(cell[d]);
      lo[d] = f < edge ? cell[d] - 1 : cell[d];
      hi[d] = f > 1.0f - edge ? cell[d] + 1 : cell[d];
    }
  }
  template <class Fn>  // fn(hash) per cell in a fixed order until it returns true
  bool any(Fn&& fn) const {
    for (int64_t x = lo[0]; x <= hi[0]; ++x)
      for (int64_t y = lo[1]; y <= hi[1]; ++y)
        for (int64_t z = lo[2]; z <= hi[2]; ++z)
          if (fn(cellHash(x, y, z))) return true;
    return false;
  }
};

constexpr uint32_t kDone = 0x80000000u;  // a corner's vertex id is set (weldMesh, step 3)

// Every step runs over fixed pieces of kPiece elements, so the result does not depend on the thread count.
constexpr size_t kPiece = size_t(1) << 16;
size_t piecesOf(size_t n) { return (n + kPiece - 1) / kPiece; }
template <class Fn>  // fn(piece, begin, end)
void forPieces(size_t n, unsigned threads, Fn&& fn) {
  parallelFor(piecesOf(n), threads, [&](size_t p) { fn(p, p * kPiece, std::min(n, (p + 1) * kPiece)); });
}
// forPieces beside a few other tasks (`beside`), which start first, one a thread: each a vector's
// resize, which value-initialises its elements in one thread's memset that would otherwise run alone.
template <class Fn>
void forPiecesBeside(std::initializer_list<std::function<void()>> beside, size_t n, unsigned threads, Fn&& fn) {
  const size_t first = beside.size();  // a parallelFor takes its indices in order: these go first
  parallelFor(first + piecesOf(n), threads, [&](size_t k) {
    if (k < first) return beside.begin()[k]();
    const size_t p = k - first;
    fn(p, p * kPiece, std::min(n, (p + 1) * kPiece));
  });
}
template <class T>  // large arrays every element of which is written before it is read: not cleared first
std::unique_ptr<T[]> uninitialised(size_t n) {
  return std::unique_ptr<T[]>(new T[n]);
}

// Items grouped by key, each group's items in increasing order: group g holds items[start[g], start[g + 1]).
struct Groups {
  std::vector<uint32_t> start{0};
  std::unique_ptr<uint32_t[]> items;
  size_t count() const { return start.size() - 1; }
};

// Items i < n with key(i) < keys (kAbsent: left out). Dense: one group per key (empty ones too), so start
// is indexed by key; else, when the keys are few against their range, only the keys that occur.
template <class Key>
Groups groupBy(size_t n, size_t keys, unsigned threads, const Key& key, bool dense) {
  Groups g;
  if (!dense && keys > 4 * n + kPiece) {  // sparse: sorted (key, item) pairs
    std::vector<uint64_t> pairs;
    for (size_t i = 0; i < n; ++i)
      if (const uint32_t k = key(i); k != kAbsent) pairs.push_back(uint64_t(k) << 32 | i);
    std::sort(pairs.begin(), pairs.end());
    g.items = uninitialised<uint32_t>(pairs.size());
    for (size_t j = 0; j < pairs.size(); ++j) {
      if (j > 0 && pairs[j] >> 32 != pairs[j - 1] >> 32) g.start.push_back(uint32_t(j));
      g.items[j] = uint32_t(pairs[j]);
    }
    if (!pairs.empty()) g.start.push_back(uint32_t(pairs.size()));
    return g;
  }
  // Counting sort in place of the counts, with no second array of the items (4 bytes an item: at 100 M
  // triangles the weld's peak of memory was this sort's): the items are counted per key and scattered on
  // all cores in whatever order the threads meet them, then each group is sorted (its items are few).
  resizeOnAllCores(g.start, keys + 1, threads);  // zeros: the count of key k goes to start[k + 1]
  auto bump = [threads](uint32_t& x) {
    return threads == 1 ? x++ : std::atomic_ref<uint32_t>(x).fetch_add(1, std::memory_order_relaxed);
  };
  forPieces(n, threads, [&](size_t, size_t b, size_t e) {
    for (size_t i = b; i < e; ++i)
      if (const uint32_t k = key(i); k != kAbsent) bump(g.start[k + 1]);
  });
  // start[k + 1] becomes the first place of group k (an exclusive sum), the cursor the scatter moves to
  // group k's end, which is group k + 1's first place: what start[k + 1] must hold.
  const size_t shards = piecesOf(keys);
  std::vector<uint32_t> shardBase(shards);
  forPieces(keys, threads, [&](size_t s, size_t b, size_t e) {
    shardBase[s] = std::accumulate(g.start.begin() + ptrdiff_t(b + 1), g.start.begin() + ptrdiff_t(e + 1), uint32_t(0));
  });
  uint32_t sum = 0;
  for (uint32_t& x : shardBase) sum += std::exchange(x, sum);
  forPieces(keys, threads, [&](size_t s, size_t b, size_t e) {
    for (size_t k = b, at = shardBase[s]; k < e; ++k) at += std::exchange(g.start[k + 1], uint32_t(at));
  });
  g.items = uninitialised<uint32_t>(sum);
  forPieces(n, threads, [&](size_t, size_t b, size_t e) {
    for (size_t i = b; i < e; ++i)
      if (const uint32_t k = key(i); k != kAbsent) g.items[bump(g.start[k + 1])] = uint32_t(i);
  });
  forPieces(keys, threads, [&](size_t, size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) std::sort(g.items.get() + g.start[k], g.items.get() + g.start[k + 1]);
  });
  return g;
}

void freeGroups(Groups& g, unsigned threads) {
  freeOnAllCores(g.items, g.start.back(), threads);
  g = Groups();
}

// Exclusive prefix sum of per-piece counts; returns the total.
size_t prefix(std::vector<size_t>& v) {
  size_t sum = 0;
  for (size_t& x : v) sum += std::exchange(x, sum);
  return sum;
}

}  // namespace

WeldCounts weldMesh(std::span<Corner> corners, std::span<const glm::vec3> positions, std::span<const glm::vec3> normals,
                    std::span<const glm::vec2> texcoords, Mesh& out, float creaseDeg, std::span<const glm::vec4> colors,
                    unsigned threads, const std::function<void()>& cornersDone, const std::function<void(const char*)>& stepFn) {
  auto step = [&](const char* name) {
    if (stepFn) stepFn(name);
  };
  WeldCounts counts;
  step("weld: 1 degenerate triangles");
  const size_t triCount = corners.size() / 3, cornerCount = triCount * 3;

  // 1. Drop triangles with a repeated corner position or zero area.
  // Large arrays are left unset where every element is written before it is read: the threads that
  // write them touch their pages first, instead of one thread clearing them.
  auto keep = uninitialised<uint8_t>(triCount);
  struct Piece {
    size_t kept = 0;
    bool needNormals = false, hasTex = false;
    uint32_t pmin = kAbsent, pmax = 0;
  };
  std::vector<Piece> pieces(piecesOf(triCount));
  forPieces(triCount, threads, [&](size_t p, size_t b, size_t e) {
    Piece& s = pieces[p];
    for (size_t t = b; t < e; ++t) {
      const Corner* c = &corners[t * 3];
      const glm::vec3 a = positions[c[0].p], bb = positions[c[1].p], d = positions[c[2].p];
      const glm::vec3 x = glm::cross(bb - a, d - a);
      keep[t] = !(c[0].p == c[1].p || c[1].p == c[2].p || c[0].p == c[2].p || !(glm::dot(x, x) > 0.0f));
      if (!keep[t]) continue;
      ++s.kept;
      for (int k = 0; k < 3; ++k) {
        s.needNormals |= c[k].n == kAbsent;
        s.hasTex |= c[k].t != kAbsent;
        s.pmin = std::min(s.pmin, c[k].p);
        s.pmax = std::max(s.pmax, c[k].p);
      }
    }
  });
  bool needNormals = false, hasTex = false;
  uint32_t pmin = kAbsent, pmax = 0;
  for (const Piece& s : pieces) {
    counts.triangles += s.kept;
    needNormals |= s.needNormals;
    hasTex |= s.hasTex;
    pmin = std::min(pmin, s.pmin);
    pmax = std::max(pmax, s.pmax);
  }
  counts.degenerate = triCount - counts.triangles;
  out.positions.clear();
  out.normals.clear();
  out.texcoords.clear();
  out.colors.clear();
  out.indices.clear();
  out.bounds = Bounds{};
  if (counts.triangles == 0) return counts;

  // The kept corners at each position, in order.
  step("weld: 1 corners grouped by position");
  Groups atPos = groupBy(
      cornerCount, size_t(pmax - pmin) + 1, threads, [&](size_t c) { return keep[c / 3] ? corners[c].p - pmin : kAbsent; },
      false);

  // 2. Normals where a corner has none: the area-weighted sum of the faces around its position whose normals
  // lie within `creaseDeg` of its own face's (180: every face, one smooth normal per position; 0: its own
  // face only, flat). The unnormalised cross product is twice the area times the normal. Such a corner
  // gets the id normals.size() + genOf[c] of a generated normal; equal sums at a position share an id.
  // Those ids are written into the corners' n (a per-corner array would be the weld's peak of memory); the
  // faces' cross products are made again per position rather than held per triangle, for the same reason.
  // The generated normals stay in their pieces' arrays (made[p], ids from base[p] on): not copied into one.
  std::vector<std::vector<glm::vec3>> made;
  std::vector<size_t> base;
  if (needNormals) {
    step("weld: 2 generated normals");
    auto cross = [&](size_t t) {  // as step 1 computes it
      const Corner* c = &corners[t * 3];
      const glm::vec3 a = positions[c[0].p];
      return glm::cross(positions[c[1].p] - a, positions[c[2].p] - a);
    };
    const float cosCrease = creaseDeg >= 180.0f ? -2.0f : std::cos(glm::radians(std::max(creaseDeg, 0.0f))) - 1e-6f;
    auto unit = [](glm::vec3 n) {
      const float l = glm::length(n);
      return l > 0.0f && std::isfinite(l) ? n / l : glm::vec3(0, 0, 1);
    };
    const uint32_t fileNormals = uint32_t(normals.size());
    made.resize(piecesOf(atPos.count()));
    forPieces(atPos.count(), threads, [&](size_t p, size_t b, size_t e) {
      std::vector<glm::vec3> crosses, units;  // of the faces at this position
      // Up to 64 faces at a position: the faces each corner's normal averages as bits (a kept triangle has one
      // corner at a position, so face i is corner i here). The crease test is symmetric (each product of
      // the dot commutes), so each pair is tested once, and a corner whose faces are those of an earlier
      // one here gets its normal: the same sum in the same order, so the same normal.
      std::vector<uint64_t> faces;
      std::vector<std::pair<uint64_t, uint32_t>> seen;  // faces, normal id
      for (size_t g = b; g < e; ++g) {
        const uint32_t *first = atPos.items.get() + atPos.start[g], *last = atPos.items.get() + atPos.start[g + 1];
        const size_t here = made[p].size(), count = size_t(last - first);  // the normals made at this position so far
        crosses.clear();
        units.clear();
        for (const uint32_t* c = first; c != last; ++c) crosses.push_back(cross(*c / 3)), units.push_back(unit(crosses.back()));
        const bool bits = count <= 64;
        seen.clear();
        if (bits) {
          faces.assign(count, 0);
          for (size_t i = 0; i < count; ++i) {
            faces[i] |= uint64_t(1) << i;
            if (creaseDeg > 0.0f)
              for (size_t j = i + 1; j < count; ++j)
                if (glm::dot(units[i], units[j]) >= cosCrease) faces[i] |= uint64_t(1) << j, faces[j] |= uint64_t(1) << i;
          }
        }
        for (const uint32_t* c = first; c != last; ++c) {
          if (corners[*c].n != kAbsent) continue;
          const size_t i = size_t(c - first);
          if (bits) {
            auto same = std::find_if(seen.begin(), seen.end(), [&](const auto& s) { return s.first == faces[i]; });
            if (same != seen.end()) {
              corners[*c].n = same->second;
              continue;
            }
          }
          glm::vec3 sum(0.0f);
          for (size_t o = 0; o < count; ++o)
            if (bits ? (faces[i] >> o & 1) : o == i || (creaseDeg > 0.0f && glm::dot(units[i], units[o]) >= cosCrease))
              sum += crosses[o];
          const glm::vec3 n = unit(sum);
          size_t k = here;
          while (k < made[p].size() && made[p][k] != n) ++k;
          if (k == made[p].size()) made[p].push_back(n);
          corners[*c].n = fileNormals + uint32_t(k);  // the piece's base is added below
          if (bits) seen.emplace_back(faces[i], corners[*c].n);
        }
      }
      made[p].shrink_to_fit();  // held to the end of step 4
    });
    base.resize(made.size());
    for (size_t p = 0; p < made.size(); ++p) base[p] = made[p].size();
    prefix(base);
    forPieces(atPos.count(), threads, [&](size_t p, size_t b, size_t e) {
      for (uint32_t i = atPos.start[b]; i < atPos.start[e]; ++i)
        if (corners[atPos.items[i]].n >= fileNormals) corners[atPos.items[i]].n += uint32_t(base[p]);
    });
  }

  // 3. Identical corners become one vertex (numbered as they first appear). Equal corners share a position,
  // so its group is all a corner is compared with; the result is written into the corners themselves (a
  // per-corner array beside them and the groups would be the weld's peak of memory): a corner equal to an
  // earlier one gets that one's index in p and kAbsent in n (every kept corner has a normal by now).
  if (cornerCount >= kDone) throw Error("a mesh of more than 715 million triangles cannot be welded");
  step("weld: 3 exact duplicates");
  forPieces(atPos.count(), threads, [&](size_t, size_t b, size_t e) {
    std::vector<uint32_t> distinct;
    for (size_t g = b; g < e; ++g) {
      distinct.clear();
      for (uint32_t i = atPos.start[g]; i < atPos.start[g + 1]; ++i) {
        const uint32_t c = atPos.items[i];
        const Corner x = corners[c];
        size_t k = 0;
        while (k < distinct.size() && !(corners[distinct[k]] == x)) ++k;
        if (k == distinct.size()) distinct.push_back(c);
        else corners[c] = {distinct[k], kAbsent, kAbsent};
      }
    }
  });
  freeGroups(atPos, threads);
  step("weld: 3 vertex ids");
  auto first = [&](size_t c) { return keep[c / 3] && corners[c].n != kAbsent; };
  const size_t cornerPieces = piecesOf(cornerCount);
  std::vector<size_t> firsts(cornerPieces, 0);
  forPieces(cornerCount, threads, [&](size_t p, size_t b, size_t e) {
    for (size_t c = b; c < e; ++c) firsts[p] += first(c);
  });
  const size_t uniqCount = prefix(firsts);
  // Each vertex's first corner is copied out, so that the corners can go before the vertices are made, and
  // gets its vertex id (kDone set); every other corner the index of the first equal one, then that one's id.
  // A piece's corners are read by it alone here, so their pages go back as it ends: the corners (12 bytes
  // each) shrink while the ids (4) grow, at what was the weld's peak of memory.
  auto uniq = uninitialised<Corner>(uniqCount);
  auto vertexOf = uninitialised<uint32_t>(cornerCount);
  forPieces(cornerCount, threads, [&](size_t p, size_t b, size_t e) {
    for (size_t c = b, id = firsts[p]; c < e; ++c)
      if (first(c)) uniq[id] = corners[c], vertexOf[c] = uint32_t(id++) | kDone;
      else if (keep[c / 3]) vertexOf[c] = corners[c].p;
    pages::drop(&corners[b], (e - b) * sizeof(Corner));
  });
  if (cornersDone) cornersDone();                                    // from here on only `keep` and the ids are read
  forPieces(cornerCount, threads, [&](size_t, size_t b, size_t e) {  // reads the entries of first corners only
    for (size_t c = b; c < e; ++c)
      if (keep[c / 3] && !(vertexOf[c] & kDone)) vertexOf[c] = vertexOf[vertexOf[c]];
  });

  // 4. Vertices within the tolerance are merged, greedy as one thread would do it: in order, each joins
  // the first earlier kept vertex found near it (cells in a fixed order, a cell's hash slot newest first),
  // else is kept. A vertex with no earlier vertex near it at all is kept for sure, which all cores decide
  // at once; the rest (rare: near but not equal) are decided in order afterwards.
  step("weld: 4 vertices gathered");
  auto verts = uninitialised<Vertex>(uniqCount);
  auto vcolor = uninitialised<glm::vec4>(colors.empty() ? 0 : uniqCount);
  auto slotOf = uninitialised<uint32_t>(uniqCount);
  auto kept = uninitialised<uint8_t>(uniqCount);  // first: whether its cells are its own alone
  size_t cap = 16;  // the hash slots one thread would use: their collisions decide which vertex is found first
  while (cap < uniqCount * 2) cap <<= 1;
  const size_t mask = cap - 1, buckets = std::max<size_t>(16, cap / 4);
  forPieces(uniqCount, threads, [&](size_t, size_t b, size_t e) {
    for (size_t u = b; u < e; ++u) {
      const Corner c = uniq[u];
      Vertex& v = verts[u];
      v.p = positions[c.p];
      if (c.n < normals.size()) {
        v.n = normals[c.n];
      } else {
        const size_t g = c.n - normals.size(), p = size_t(std::upper_bound(base.begin(), base.end(), g) - base.begin()) - 1;
        v.n = made[p][g - base[p]];
      }
      v.t = c.t != kAbsent ? texcoords[c.t] : glm::vec2(0.0f);
      if (!colors.empty()) vcolor[u] = colors[c.p];
      const Around a(v.p);
      slotOf[u] = uint32_t(cellHash(a.cell[0], a.cell[1], a.cell[2]) & mask);
      kept[u] = a.lo[0] == a.hi[0] && a.lo[1] == a.hi[1] && a.lo[2] == a.hi[2];
    }
  });
  freeOnAllCores(uniq, uniqCount, threads);
  std::vector<std::vector<glm::vec3>>().swap(made);
  auto isNear = [&](uint32_t a, uint32_t b) { return near(verts[a], verts[b]) && (colors.empty() || vcolor[a] == vcolor[b]); };
  step("weld: 4 near test");
  Groups inBucket = groupBy(
      uniqCount, buckets, threads, [&](size_t u) { return slotOf[u] & (buckets - 1); }, true);
  auto target = uninitialised<uint32_t>(uniqCount);  // the vertex each one joins (itself when kept)
  // Bucket by bucket: a vertex whose cells are its own alone (most: it lies within the tolerance of no
  // cell face) needs only the bucket's vertices before it, which were just read; vertex by vertex, every
  // look-up was a chain of cache misses (bucket, its items, their vertices).
  forPieces(buckets, threads, [&](size_t, size_t b, size_t e) {
    for (size_t k = b; k < e; ++k)
      for (uint32_t j = inBucket.start[k]; j < inBucket.start[k + 1]; ++j) {
        const uint32_t u = inBucket.items[j];
        bool near_ = false;
        if (kept[u]) {  // its own cell, in this bucket: the first there reads no vertex (a cache miss each)
          for (uint32_t i = inBucket.start[k]; i < j && !near_; ++i) near_ = isNear(inBucket.items[i], u);
        } else {
          near_ = Around(verts[u].p).any([&](uint64_t h) {
            const size_t c = h & (buckets - 1);
            for (uint32_t i = inBucket.start[c]; i < inBucket.start[c + 1] && inBucket.items[i] < u; ++i)
              if (isNear(inBucket.items[i], u)) return true;
            return false;
          });
        }
        kept[u] = !near_;
        if (!near_) target[u] = u;
      }
  });
  std::vector<std::vector<uint32_t>> open(piecesOf(uniqCount));  // near an earlier vertex: decided in order below
  forPieces(uniqCount, threads, [&](size_t p, size_t b, size_t e) {
    for (size_t u = b; u < e; ++u)
      if (!kept[u]) open[p].push_back(uint32_t(u));
  });
  step("weld: 4 near but not equal (one thread)");
  for (const std::vector<uint32_t>& list : open)
    for (const uint32_t u : list) {
      uint32_t found = kAbsent;
      Around(verts[u].p).any([&](uint64_t h) {
        const uint32_t slot = uint32_t(h & mask);
        const size_t k = slot & (buckets - 1);
        for (uint32_t i = inBucket.start[k + 1]; i-- > inBucket.start[k];) {
          const uint32_t w = inBucket.items[i];
          if (w < u && kept[w] && slotOf[w] == slot && isNear(w, u)) return found = w, true;
        }
        return false;
      });
      if (found == kAbsent) kept[u] = 1, found = u;
      target[u] = found;
    }
  step("weld: 4 kept ids");
  freeGroups(inBucket, threads);
  freeOnAllCores(slotOf, uniqCount, threads);
  std::vector<size_t> keptBefore(piecesOf(uniqCount), 0);
  forPieces(uniqCount, threads, [&](size_t p, size_t b, size_t e) {
    for (size_t u = b; u < e; ++u) keptBefore[p] += kept[u];
  });
  counts.vertices = prefix(keptBefore);

  // 5. Emit. A vector's resize value-initialises its elements in one thread's memset (at 100 M triangles
  // 2.9 GB of them: with the arrays one after another, most of this step's wall time, 12 of 16 cores
  // idle). The arrays' pages are made on all cores, then the vertex arrays' resizes run side by side
  // beside the kept vertices' ids, and the index array's (after the gathered vertices are freed: the
  // weld's memory as before) beside the count of the triangles kept. It is sized for the triangles
  // before that count (a bound, so that it need not wait for it), then shrunk (no memset).
  step("weld: 5 mesh emitted");
  const size_t n = counts.vertices;
  std::vector<glm::vec3>&pos = out.positions.writable(), &nrm = out.normals.writable();
  std::vector<glm::vec2>& tex = out.texcoords.writable();
  std::vector<glm::vec4>& col = out.colors.writable();
  std::vector<uint32_t>& idx = out.indices.writable();
  const size_t texCount = hasTex ? n : 0, colCount = colors.empty() ? 0 : n;
  reserveOnAllCores(pos, n, threads);
  reserveOnAllCores(nrm, n, threads);
  reserveOnAllCores(tex, texCount, threads);
  reserveOnAllCores(col, colCount, threads);
  auto keptId = uninitialised<uint32_t>(uniqCount);
  forPiecesBeside({[&] { pos.resize(n); }, [&] { nrm.resize(n); }, [&] { tex.resize(texCount); }, [&] { col.resize(colCount); }},
                  uniqCount, threads, [&](size_t p, size_t b, size_t e) {
                    for (size_t u = b, id = keptBefore[p]; u < e; ++u)
                      if (kept[u]) keptId[u] = uint32_t(id++);
                  });
  std::vector<Bounds> bounds(piecesOf(uniqCount));
  forPieces(uniqCount, threads, [&](size_t p, size_t b, size_t e) {
    for (size_t u = b; u < e; ++u) {
      if (!kept[u]) continue;
      const size_t r = keptId[u];
      pos[r] = verts[u].p;
      nrm[r] = verts[u].n;
      if (hasTex) tex[r] = verts[u].t;
      if (!colors.empty()) col[r] = vcolor[u];
      bounds[p].extend(verts[u].p);
    }
  });
  for (const Bounds& b : bounds) out.bounds.extend(b);
  freeOnAllCores(verts, uniqCount, threads);
  freeOnAllCores(vcolor, colors.empty() ? 0 : uniqCount, threads);
  // Welding can collapse a sliver triangle onto an edge; such triangles are dropped too. The count turns
  // each kept corner's vertex id into its kept vertex's (in place: no corner reads another's by now), so
  // that the write reads them in order.
  auto sliver = [](uint32_t x, uint32_t y, uint32_t z) { return x == y || y == z || x == z; };
  const size_t idxBound = counts.triangles * 3;
  reserveOnAllCores(idx, idxBound, threads);
  std::vector<size_t> written(pieces.size(), 0);
  forPiecesBeside({[&] { idx.resize(idxBound); }}, triCount, threads, [&](size_t p, size_t b, size_t e) {
    for (size_t t = b; t < e; ++t) {
      if (!keep[t]) continue;
      uint32_t* v = &vertexOf[t * 3];
      for (int k = 0; k < 3; ++k) v[k] = keptId[target[v[k] & ~kDone]];
      written[p] += !sliver(v[0], v[1], v[2]);
    }
  });
  freeOnAllCores(target, uniqCount, threads);
  freeOnAllCores(keptId, uniqCount, threads);
  const size_t triangles = prefix(written);
  counts.degenerate += counts.triangles - triangles;
  counts.triangles = triangles;
  forPieces(triCount, threads, [&](size_t p, size_t b, size_t e) {
    for (size_t t = b, at = written[p] * 3; t < e; ++t) {
      const uint32_t* v = &vertexOf[t * 3];
      if (keep[t] && !sliver(v[0], v[1], v[2])) idx[at] = v[0], idx[at + 1] = v[1], idx[at + 2] = v[2], at += 3;
    }
  });
  idx.resize(triangles * 3);  // a shrink: nothing written
  freeOnAllCores(vertexOf, cornerCount, threads);
  return counts;
}

}  // namespace rtr
