#include "scene/weld.hpp"

#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

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

struct Vertex {
  glm::vec3 p, n;
  glm::vec2 t;
  glm::vec4 c;  // vertex colour; 0 when the file has none
};

inline bool near(const Vertex& a, const Vertex& b) {
  auto c = [](float x, float y) { return std::fabs(x - y) <= kWeldTolerance; };
  return c(a.p.x, b.p.x) && c(a.p.y, b.p.y) && c(a.p.z, b.p.z) && c(a.n.x, b.n.x) && c(a.n.y, b.n.y) && c(a.n.z, b.n.z) &&
         c(a.t.x, b.t.x) && c(a.t.y, b.t.y) && a.c == b.c;
}

}  // namespace

WeldCounts weldMesh(std::span<const Corner> corners, std::span<const glm::vec3> positions, std::span<const glm::vec3> normals,
                    std::span<const glm::vec2> texcoords, Mesh& out, float creaseDeg, std::span<const glm::vec4> colors) {
  WeldCounts counts;
  const size_t triCount = corners.size() / 3;

  // 1. Drop triangles with a repeated corner position or zero area.
  std::vector<uint8_t> keep(triCount, 0);
  bool needNormals = false, hasTex = false;
  for (size_t t = 0; t < triCount; ++t) {
    const Corner* c = &corners[t * 3];
    const glm::vec3 a = positions[c[0].p], b = positions[c[1].p], d = positions[c[2].p];
    const glm::vec3 x = glm::cross(b - a, d - a);
    const float area2 = glm::dot(x, x);
    if (c[0].p == c[1].p || c[1].p == c[2].p || c[0].p == c[2].p || !(area2 > 0.0f)) {
      ++counts.degenerate;
      continue;
    }
    keep[t] = 1;
    ++counts.triangles;
    for (int k = 0; k < 3; ++k) {
      needNormals |= c[k].n == kAbsent;
      hasTex |= c[k].t != kAbsent;
    }
  }

  // 2. Normals where a corner has none: the area-weighted sum of the faces around its position whose normals
  // lie within `creaseDeg` of its own face's (180: every face, one smooth normal per position; 0: its own
  // face only, flat). The unnormalised cross product is twice the area times the normal. Such corners get
  // the id normals.size() + k of generated normal k; equal sums at a position share an id.
  // Per-thread tables over all positions, reset after each mesh: neighbouring faces share nearby
  // positions, so direct indexing stays in cache where a hash table would not.
  thread_local std::vector<uint32_t> headByPos, normalOfPos;
  if (headByPos.size() < positions.size()) headByPos.assign(positions.size(), kAbsent);
  if (needNormals && normalOfPos.size() < positions.size()) normalOfPos.assign(positions.size(), kAbsent);
  std::vector<glm::vec3> gen;
  std::vector<uint32_t> accumPos;  // positions with an entry in normalOfPos (a local id)
  std::vector<Corner> filled;
  if (needNormals) {
    std::vector<glm::vec3> cross(triCount);
    std::vector<uint32_t> start(1, 0);  // faces around local position i: around[start[i], start[i + 1])
    for (size_t t = 0; t < triCount; ++t) {
      if (!keep[t]) continue;
      const Corner* c = &corners[t * 3];
      const glm::vec3 a = positions[c[0].p];
      cross[t] = glm::cross(positions[c[1].p] - a, positions[c[2].p] - a);
      for (int k = 0; k < 3; ++k) {
        uint32_t& id = normalOfPos[c[k].p];
        if (id == kAbsent) id = uint32_t(accumPos.size()), accumPos.push_back(c[k].p), start.push_back(0);
        ++start[id + 1];
      }
    }
    for (size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
    std::vector<uint32_t> around(start.back()), fill(start.begin(), start.end() - 1);
    for (size_t t = 0; t < triCount; ++t)
      if (keep[t])
        for (int k = 0; k < 3; ++k) around[fill[normalOfPos[corners[t * 3 + k].p]]++] = uint32_t(t);
    const float cosCrease = creaseDeg >= 180.0f ? -2.0f : std::cos(glm::radians(std::max(creaseDeg, 0.0f))) - 1e-6f;
    auto unit = [](glm::vec3 n) {
      const float l = glm::length(n);
      return l > 0.0f && std::isfinite(l) ? n / l : glm::vec3(0, 0, 1);
    };
    std::vector<uint32_t> firstGen(accumPos.size(), kAbsent), nextGen;  // generated normals per position
    filled.assign(corners.begin(), corners.end());
    for (size_t t = 0; t < triCount; ++t) {
      if (!keep[t]) continue;
      const glm::vec3 own = unit(cross[t]);
      for (int k = 0; k < 3; ++k) {
        Corner& c = filled[t * 3 + k];
        if (c.n != kAbsent) continue;
        const uint32_t lp = normalOfPos[c.p];
        glm::vec3 sum(0.0f);
        for (uint32_t i = start[lp]; i < start[lp + 1]; ++i)
          if (around[i] == t || (creaseDeg > 0.0f && glm::dot(own, unit(cross[around[i]])) >= cosCrease)) sum += cross[around[i]];
        const glm::vec3 n = unit(sum);
        uint32_t g = firstGen[lp];
        while (g != kAbsent && gen[g] != n) g = nextGen[g];
        if (g == kAbsent) {
          g = uint32_t(gen.size());
          gen.push_back(n);
          nextGen.push_back(firstGen[lp]);
          firstGen[lp] = g;
        }
        c.n = uint32_t(normals.size()) + g;
      }
    }
    corners = filled;
  }

  // 3. Identical corners become one vertex; 4. vertices within the tolerance are merged (greedy,
  // first come first kept, so the result does not depend on hashing).
  // Corners are found through their position index (headByPos), chained when they differ in t or n.
  std::vector<Corner> uniq;
  std::vector<uint32_t> nextSame;  // chain of corners sharing a position
  uniq.reserve(counts.triangles + 16);
  nextSame.reserve(counts.triangles + 16);
  std::vector<uint32_t> cornerVertex(counts.triangles * 3);
  size_t ci = 0;
  for (size_t t = 0; t < triCount; ++t) {
    if (!keep[t]) continue;
    for (int k = 0; k < 3; ++k) {
      const Corner& c = corners[t * 3 + k];
      uint32_t id = headByPos[c.p];
      while (id != kAbsent && !(uniq[id] == c)) id = nextSame[id];
      if (id == kAbsent) {
        id = uint32_t(uniq.size());
        uniq.push_back(c);
        nextSame.push_back(headByPos[c.p]);
        headByPos[c.p] = id;
      }
      cornerVertex[ci++] = id;
    }
  }
  for (const Corner& c : uniq) headByPos[c.p] = kAbsent;

  std::vector<uint32_t> slots;
  size_t cap = 16;
  while (cap < uniq.size() * 2) cap <<= 1;
  slots.assign(cap, kAbsent);
  const size_t mask = cap - 1;
  std::vector<uint32_t> next;  // chain of representatives per bucket
  std::vector<Vertex> reps;
  std::vector<uint32_t> remap(uniq.size());
  reps.reserve(uniq.size());
  next.reserve(uniq.size());
  const float edge = kWeldTolerance * kCellScale;

  for (size_t u = 0; u < uniq.size(); ++u) {
    const Corner& c = uniq[u];
    Vertex v;
    v.p = positions[c.p];
    v.n = c.n < normals.size() ? normals[c.n] : gen[c.n - normals.size()];
    v.t = c.t != kAbsent ? texcoords[c.t] : glm::vec2(0.0f);
    v.c = colors.empty() ? glm::vec4(0.0f) : colors[c.p];
    int64_t cell[3], lo[3], hi[3];
    for (int d = 0; d < 3; ++d) {
      cell[d] = cellOf(v.p[d]);
      float f = v.p[d] * kCellScale - float(cell[d]);
      lo[d] = f < edge ? cell[d] - 1 : cell[d];
      hi[d] = f > 1.0f - edge ? cell[d] + 1 : cell[d];
    }
    uint32_t found = kAbsent;
    for (int64_t x = lo[0]; x <= hi[0] && found == kAbsent; ++x)
      for (int64_t y = lo[1]; y <= hi[1] && found == kAbsent; ++y)
        for (int64_t z = lo[2]; z <= hi[2] && found == kAbsent; ++z)
          for (uint32_t r = slots[cellHash(x, y, z) & mask]; r != kAbsent; r = next[r])
            if (near(reps[r], v)) {
              found = r;
              break;
            }
    if (found == kAbsent) {
      found = uint32_t(reps.size());
      uint32_t& head = slots[cellHash(cell[0], cell[1], cell[2]) & mask];
      next.push_back(head);
      head = found;
      reps.push_back(v);
    }
    remap[u] = found;
  }

  for (uint32_t p : accumPos) normalOfPos[p] = kAbsent;

  // 5. Emit.
  out.positions.resize(reps.size());
  out.normals.resize(reps.size());
  out.texcoords.resize(hasTex ? reps.size() : 0);
  out.colors.resize(colors.empty() ? 0 : reps.size());
  out.bounds = Bounds{};
  for (size_t r = 0; r < reps.size(); ++r) {
    out.positions[r] = reps[r].p;
    out.normals[r] = reps[r].n;
    if (hasTex) out.texcoords[r] = reps[r].t;
    if (!colors.empty()) out.colors[r] = reps[r].c;
    out.bounds.extend(reps[r].p);
  }
  // Welding can collapse a sliver triangle onto an edge; such triangles are dropped too.
  out.indices.clear();
  out.indices.reserve(cornerVertex.size());
  for (size_t i = 0; i < cornerVertex.size(); i += 3) {
    uint32_t a = remap[cornerVertex[i]], b = remap[cornerVertex[i + 1]], c = remap[cornerVertex[i + 2]];
    if (a == b || b == c || a == c) {
      ++counts.degenerate;
      --counts.triangles;
      continue;
    }
    out.indices.insert(out.indices.end(), {a, b, c});
  }
  counts.vertices = reps.size();
  return counts;
}

}  // namespace rtr
