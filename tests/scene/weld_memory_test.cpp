// What the weld holds beside a mesh's corners (at 100 M triangles the bake's peak of memory is the
// largest mesh's weld). Every allocation of this test binary is counted, so that the peak of live bytes
// during weldMesh can be compared with what the design says it needs: beside the corners (12 bytes each,
// given back through cornersDone), a vertex id per corner (4 bytes) and 24 bytes per distinct corner (its
// copy and its generated normal), plus a flag per triangle. A second array per corner (the first-equal
// ids, the counting sort's copy of the groups) goes past it.
#include <malloc.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>

#include <gtest/gtest.h>

#include "scene/weld.hpp"

namespace {
std::atomic<size_t> live{0}, peak{0};

void* counted(size_t n) {
  void* p = std::malloc(n ? n : 1);
  if (!p) throw std::bad_alloc();
  const size_t now = live.fetch_add(malloc_usable_size(p)) + malloc_usable_size(p);
  for (size_t was = peak.load(); now > was && !peak.compare_exchange_weak(was, now);) {}
  return p;
}
void uncounted(void* p) {
  if (!p) return;
  live.fetch_sub(malloc_usable_size(p));
  std::free(p);
}
}  // namespace

void* operator new(size_t n) { return counted(n); }
void* operator new[](size_t n) { return counted(n); }
void operator delete(void* p) noexcept { uncounted(p); }
void operator delete[](void* p) noexcept { uncounted(p); }
void operator delete(void* p, size_t) noexcept { uncounted(p); }
void operator delete[](void* p, size_t) noexcept { uncounted(p); }

using namespace rtr;

TEST(WeldMemory, HoldsAVertexIdPerCornerBesideTheCorners) {
  // A smooth height field without normals (all generated), like the temple's statue: about six corners
  // per vertex, no two vertices within the tolerance (so the vertices counted are the distinct corners).
  const int side = 400;
  std::vector<glm::vec3> positions;
  std::vector<glm::vec2> texcoords;
  for (int j = 0; j <= side; ++j)
    for (int i = 0; i <= side; ++i) {
      positions.push_back({float(i) * 1e-2f, float(j) * 1e-2f, 0.1f * std::sin(float(i) * 0.05f) * std::cos(float(j) * 0.07f)});
      texcoords.push_back({float(i) / side, float(j) / side});
    }
  auto corners = std::make_unique<std::vector<Corner>>();
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i) {
      const uint32_t a = uint32_t(j * (side + 1) + i), b = a + 1, c = a + side + 2, d = a + side + 1;
      for (uint32_t p : {a, b, c, a, c, d}) corners->push_back({p, p, kAbsent});
    }
  const size_t cornerCount = corners->size();
  for (unsigned threads : {1u, 2u}) {
    std::vector<Corner> copy = *corners;
    auto held = std::make_unique<std::vector<Corner>>(std::move(copy));
    Mesh mesh;
    const size_t before = live.load();
    peak = before;
    const WeldCounts counts = weldMesh(*held, positions, {}, texcoords, mesh, 180.0f, {}, threads, [&] { held.reset(); });
    const size_t beside = peak.load() - before;
    ASSERT_EQ(counts.vertices, positions.size());
    ASSERT_EQ(counts.triangles, cornerCount / 3);
    EXPECT_EQ(held, nullptr) << "cornersDone was not called";
    const size_t design = 4 * cornerCount + 24 * counts.vertices + cornerCount / 3 + (size_t(256) << 10);
    EXPECT_LE(beside, design) << threads << " threads: " << double(beside) / double(cornerCount)
                              << " bytes per corner beside the corners' 12";
  }
}
