// The weld on all cores: the same mesh for any thread count (fixed pieces), and what a weld promises on
// a mesh large enough to span many pieces: every corner keeps its attributes within the tolerance, no two
// vertices are within the tolerance of each other, degenerate triangles are dropped.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "scene/weld.hpp"
#include "scene_compare.hpp"

using namespace rtr;

namespace {

// A grid of quads written twice as a soup with copies of its vertices, some moved by less than the tolerance,
// some by more; normals on some triangles only (the rest generated), colours, a few degenerate triangles.
struct Soup {
  std::vector<Corner> corners;
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> texcoords;
  std::vector<glm::vec4> colors;
};

Soup makeSoup(int side, unsigned seed) {
  Soup s;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick(0, 99);
  s.normals = {{0, 0, 1}, {0, 1, 0}};
  auto vertex = [&](int i, int j) {
    float jitter = 0.0f;
    // Steps of 6e-6: a copy near another that is near a third, so which copies stay depends on the order.
    if (const int r = pick(rng); r < 30) jitter = 6e-6f * float(1 + r % 3);
    else if (r < 35) jitter = 3e-5f;  // beyond the tolerance
    const float h = 0.01f * std::sin(float(i) * 0.3f) * std::cos(float(j) * 0.2f);
    s.positions.push_back({float(i) * 1e-3f + jitter, float(j) * 1e-3f, h});
    s.colors.push_back({1.0f, pick(rng) < 3 ? 0.5f : 1.0f, 1.0f, 1.0f});
    s.texcoords.push_back({float(i) / float(side), float(j) / float(side) + jitter});
    return uint32_t(s.positions.size() - 1);
  };
  for (int pass = 0; pass < 2; ++pass)  // twice: near copies far apart in the soup, in other pieces
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i) {
        const uint32_t a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1), d = vertex(i, j + 1);
        const uint32_t n = pick(rng) < 50 ? kAbsent : uint32_t(pick(rng) % 2);
        const uint32_t t = pick(rng) < 90 ? 0 : kAbsent;
        auto corner = [&](uint32_t p) { return Corner{p, t == kAbsent ? kAbsent : p, n}; };
        for (uint32_t p : {a, b, c, a, c, pick(rng) < 2 ? a : d}) s.corners.push_back(corner(p));
      }
  return s;
}

Mesh weld(const Soup& s, unsigned threads, WeldCounts* counts = nullptr) {
  Mesh m;
  std::vector<Corner> corners = s.corners;  // the weld writes generated normals' ids into them
  const WeldCounts c = weldMesh(corners, s.positions, s.normals, s.texcoords, m, 40.0f, s.colors, threads);
  if (counts) *counts = c;
  return m;
}

bool near(const Mesh& m, size_t a, size_t b) {
  auto c = [](float x, float y) { return std::fabs(x - y) <= kWeldTolerance; };
  for (int d = 0; d < 3; ++d)
    if (!c(m.positions[a][d], m.positions[b][d]) || !c(m.normals[a][d], m.normals[b][d])) return false;
  return c(m.texcoords[a].x, m.texcoords[b].x) && c(m.texcoords[a].y, m.texcoords[b].y) && m.colors[a] == m.colors[b];
}

}  // namespace

TEST(Weld, SameMeshOnAnyThreadCount) {
  const Soup s = makeSoup(190, 1);  // 144 k triangles: corners, vertices and triangles span several pieces
  WeldCounts one{}, many{};
  const Mesh a = weld(s, 1, &one);
  ASSERT_GT(a.positions.size(), size_t(1) << 17);
  for (unsigned threads : {2u, 3u, 8u}) {
    SCOPED_TRACE(threads);
    const Mesh b = weld(s, threads, &many);
    rtr::test::expectSameMesh(a, b);
    EXPECT_EQ(one.vertices, many.vertices);
    EXPECT_EQ(one.triangles, many.triangles);
    EXPECT_EQ(one.degenerate, many.degenerate);
  }
}

TEST(Weld, KeepsCornersWithinTheToleranceAndNoTwoVerticesNear) {
  const Soup s = makeSoup(100, 2);
  WeldCounts counts{};
  const Mesh m = weld(s, 4, &counts);
  EXPECT_GT(counts.degenerate, 0u);
  EXPECT_EQ(m.indices.size(), counts.triangles * 3);
  EXPECT_EQ(m.positions.size(), counts.vertices);
  // No two vertices near: compare each with the vertices in its own and the neighbouring 1e-3 columns.
  std::vector<std::vector<size_t>> column(200);
  for (size_t v = 0; v < m.positions.size(); ++v) column[size_t(std::lround(m.positions[v].x * 1e3f))].push_back(v);
  size_t pairs = 0;
  for (size_t c = 0; c < column.size(); ++c)
    for (size_t v : column[c])
      for (size_t d = c ? c - 1 : 0; d <= c + 1 && d < column.size(); ++d)
        for (size_t w : column[d])
          if (w > v) pairs += near(m, v, w);
  EXPECT_EQ(pairs, 0u);
  // Every kept triangle's corners are its soup corners' positions within the tolerance, and their colours.
  size_t t = 0, checked = 0, colours = 0;
  for (size_t k = 0; k + 2 < s.corners.size() && t * 3 < m.indices.size(); k += 3) {
    const glm::vec3 p = s.positions[s.corners[k].p];
    const glm::vec3 q = m.positions[m.indices[t * 3]];
    if (std::fabs(p.x - q.x) > kWeldTolerance || std::fabs(p.y - q.y) > kWeldTolerance) continue;  // a dropped triangle
    for (int i = 0; i < 3; ++i) {
      const glm::vec3 a = s.positions[s.corners[k + i].p], b = m.positions[m.indices[t * 3 + i]];
      EXPECT_LE(glm::length(a - b), 2e-5f);
      colours += s.colors[s.corners[k + i].p] == m.colors[m.indices[t * 3 + i]];  // colours are welded only when equal
    }
    ++t, ++checked;
  }
  EXPECT_GT(checked, m.indices.size() / 3 / 2);
  EXPECT_EQ(colours, checked * 3);
}

// The owner may free the corners once the weld calls cornersDone: nothing read after it changes the mesh.
TEST(Weld, CornersAreReadNoMoreOnceDone) {
  const Soup s = makeSoup(120, 3);
  const Mesh a = weld(s, 3);
  for (unsigned threads : {1u, 3u}) {
    std::vector<Corner> corners = s.corners;
    int calls = 0;
    Mesh b;
    weldMesh(corners, s.positions, s.normals, s.texcoords, b, 40.0f, s.colors, threads, [&] {
      ++calls;
      std::fill(corners.begin(), corners.end(), Corner{0, 0, 0});  // valid indices, wrong corners
    });
    EXPECT_EQ(calls, 1);
    rtr::test::expectSameMesh(a, b);
  }
}

// Triangles the weld itself collapses (slivers whose third corner lies within the tolerance of their
// first) are dropped after the count of those kept: the index array holds exactly the others, in order, at
// any thread count, across several pieces of triangles.
TEST(Weld, DropsTheSliversItCollapsesAndKeepsTheRestInOrder) {
  constexpr int kSide = 300;  // 180 k triangles and 9 k slivers: three pieces
  std::vector<glm::vec3> positions;
  for (int j = 0; j <= kSide; ++j)
    for (int i = 0; i <= kSide; ++i) positions.push_back({float(i) * 1e-3f, float(j) * 1e-3f, 0.0f});
  auto at = [](int i, int j) { return uint32_t(j * (kSide + 1) + i); };
  std::vector<Corner> soup;
  std::vector<uint32_t> expected;  // the soup's positions of the triangles kept, in order
  size_t slivers = 0;
  for (int j = 0; j < kSide; ++j)
    for (int i = 0; i < kSide; ++i) {
      const uint32_t a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      for (uint32_t p : {a, b, c, a, c, d}) soup.push_back({p, kAbsent, kAbsent}), expected.push_back(p);
      if ((i + j) % 10 == 0) {  // a, b and a point 5e-6 from a: area, so step 1 keeps it; the weld does not
        positions.push_back(positions[a] + glm::vec3(4e-6f, 3e-6f, 0.0f));
        for (uint32_t p : {a, b, uint32_t(positions.size() - 1)}) soup.push_back({p, kAbsent, kAbsent});
        ++slivers;
      }
    }
  ASSERT_GT(slivers, 8000u);
  for (unsigned threads : {1u, 2u, 3u, 8u}) {
    SCOPED_TRACE(threads);
    std::vector<Corner> corners = soup;
    Mesh m;
    const WeldCounts counts = weldMesh(corners, positions, {}, {}, m, 40.0f, {}, threads);
    EXPECT_EQ(counts.degenerate, slivers);
    EXPECT_EQ(counts.triangles, expected.size() / 3);
    EXPECT_EQ(counts.vertices, size_t(kSide + 1) * (kSide + 1));
    ASSERT_EQ(m.indices.size(), expected.size());
    size_t wrong = 0;
    for (size_t k = 0; k < expected.size(); ++k) wrong += m.positions[m.indices[k]] != positions[expected[k]];
    EXPECT_EQ(wrong, 0u);
  }
}
