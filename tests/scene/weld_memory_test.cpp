// What the weld holds beside a mesh's corners (at 100 M triangles the bake's peak of memory is the
// largest mesh's weld). Every allocation of this test binary is counted, so that the peak of live bytes
// during weldMesh can be compared with what the design says it needs: beside the corners (12 bytes each,
// given back through cornersDone), a vertex id per corner (4 bytes) and 24 bytes per distinct corner (its
// copy and its generated normal), plus a flag per triangle. A second array per corner (the first-equal
// ids, the counting sort's copy of the groups) goes past it.
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

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

namespace {
// A smooth height field without normals (all generated), like the temple's statue: about six corners
// per vertex, no two vertices within the tolerance (so the vertices counted are the distinct corners).
struct Field {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec2> texcoords;
  std::vector<Corner> corners;
};
Field field(int side) {
  Field f;
  for (int j = 0; j <= side; ++j)
    for (int i = 0; i <= side; ++i) {
      f.positions.push_back({float(i) * 1e-2f, float(j) * 1e-2f, 0.1f * std::sin(float(i) * 0.05f) * std::cos(float(j) * 0.07f)});
      f.texcoords.push_back({float(i) / float(side), float(j) / float(side)});
    }
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i) {
      const uint32_t a = uint32_t(j * (side + 1) + i), b = a + 1, c = a + side + 2, d = a + side + 1;
      for (uint32_t p : {a, b, c, a, c, d}) f.corners.push_back({p, p, kAbsent});
    }
  return f;
}
}  // namespace

TEST(WeldMemory, HoldsAVertexIdPerCornerBesideTheCorners) {
  const Field f = field(400);
  const std::vector<glm::vec3>& positions = f.positions;
  const std::vector<glm::vec2>& texcoords = f.texcoords;
  auto corners = std::make_unique<std::vector<Corner>>(f.corners);
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

// The corners' pages go back while the vertex ids are made (the ids grow as the corners shrink), not only
// when the caller frees them: here the caller keeps them, in a mapping of their own.
TEST(WeldMemory, GivesTheCornersPagesBackAsItGoes) {
  const Field f = field(400);
  const size_t bytes = f.corners.size() * sizeof(Corner), page = size_t(::sysconf(_SC_PAGESIZE));
  void* map = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(map, MAP_FAILED);
  ::madvise(map, bytes, MADV_NOHUGEPAGE);  // residency counted page by page
  std::copy(f.corners.begin(), f.corners.end(), static_cast<Corner*>(map));
  std::vector<unsigned char> resident((bytes + page - 1) / page);
  auto residentPages = [&] {
    ::mincore(map, bytes, resident.data());
    size_t n = 0;
    for (unsigned char r : resident) n += r & 1;
    return n;
  };
  ASSERT_EQ(residentPages(), resident.size());
  Mesh mesh;
  weldMesh({static_cast<Corner*>(map), f.corners.size()}, f.positions, {}, f.texcoords, mesh, 180.0f, {}, 2);
  EXPECT_EQ(mesh.positions.size(), f.positions.size());
  // A page shared by two of the weld's pieces of corners stays: at most one per piece.
  const size_t pieces = (f.corners.size() + 65535) / 65536;
  EXPECT_LE(residentPages(), pieces) << "of " << resident.size() << " pages";
  ::munmap(map, bytes);
}
