// A loaded .rtrscene's large arrays are views of the mapped file (no copy), kept alive by the scene's
// arrays themselves; code that changes a loaded scene copies what it changes, once, and the result is
// what the same change makes of a scene decoded into vectors.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include <gtest/gtest.h>

#include "core/input_file.hpp"
#include "scene/cluster_lod.hpp"
#include "scene/clusters.hpp"
#include "scene/first_look.hpp"
#include "scene/mesh_ops.hpp"
#include "scene/rtrscene.hpp"
#include "scene_compare.hpp"

namespace rtr {
namespace {

// A wavy grid of (n + 1)² vertices with every attribute; past 65 536 vertices its indices are 32-bit.
Mesh grid(uint32_t n, const std::string& name) {
  Mesh m;
  m.name = name;
  for (uint32_t y = 0; y <= n; ++y)
    for (uint32_t x = 0; x <= n; ++x) {
      const glm::vec3 p(float(x), 0.3f * std::sin(0.7f * x) * std::cos(0.5f * y), float(y));
      m.positions.push_back(p);
      m.bounds.extend(p);
      m.texcoords.push_back({x / float(n), y / float(n)});
      m.texcoords1.push_back({y / float(n), x / float(n)});
      m.tangents.push_back({1, 0, 0, 1});
      m.colors.push_back({x / float(n), 0.5f, y / float(n), 1});
    }
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      const uint32_t a = y * (n + 1) + x;
      m.indices.insert(m.indices.end(), {a, a + n + 1, a + 1, a + 1, a + n + 1, a + n + 2});
    }
  m.normals.assign(m.positions.size(), {0, 1, 0});
  return m;
}

Scene twoGrids() {
  Scene s;
  s.materials.push_back({});
  s.meshes.push_back(grid(259, "big"));   // 67 600 vertices: 32-bit indices
  s.meshes.push_back(grid(20, "small"));  // 16-bit indices, widened when read
  buildMissingClusters(s);
  s.meshes[0].lod = buildClusterLod(s.meshes[0]);
  return s;
}

std::span<const uint8_t> span(const std::string& b) { return {reinterpret_cast<const uint8_t*>(b.data()), b.size()}; }

struct TempFile {
  std::filesystem::path path = std::filesystem::temp_directory_path() / ("rtr-views-" + std::to_string(::getpid()) + ".rtrscene");
  explicit TempFile(const std::string& bytes) {
    std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
  }
  ~TempFile() { std::filesystem::remove(path); }
};

// `a` is a view of the mapped file `file` whose bytes at its address are the array's.
template <class T>
void expectViewOfFile(const ViewOrVector<T>& a, const std::shared_ptr<const MappedFile>& file, const char* what) {
  SCOPED_TRACE(what);
  ASSERT_FALSE(a.empty());
  ASSERT_TRUE(a.isView());
  EXPECT_EQ(a.owner(), std::static_pointer_cast<const void>(file));
  const uint8_t *b = file->bytes().data(), *p = reinterpret_cast<const uint8_t*>(a.data());
  EXPECT_TRUE(p >= b && p + a.size() * sizeof(T) <= b + file->bytes().size());
}

template <class T>
void expectOwned(const ViewOrVector<T>& a, const char* what) {
  EXPECT_FALSE(a.isView()) << what;
  EXPECT_EQ(a.owner(), nullptr) << what;
}

TEST(RtrSceneViews, ALoadedScenesArraysAreViewsOfTheMappedFile) {
  const Scene want = twoGrids();
  ASSERT_GE(want.meshes[0].lod.levels, 2u);
  const std::string bytes = encodeRtrScene(want);
  const TempFile file(bytes);
  const Scene got = loadRtrScene(file.path);
  const Mesh &big = got.meshes[0], &small = got.meshes[1];
  const auto mapped = std::static_pointer_cast<const MappedFile>(big.positions.owner());
  ASSERT_NE(mapped, nullptr);
  expectViewOfFile(big.positions, mapped, "positions");
  expectViewOfFile(big.normals, mapped, "normals");
  expectViewOfFile(big.texcoords, mapped, "texcoords");
  expectViewOfFile(big.texcoords1, mapped, "texcoords1");
  expectViewOfFile(big.tangents, mapped, "tangents");
  expectViewOfFile(big.colors, mapped, "colors");
  expectViewOfFile(big.indices, mapped, "indices");
  expectViewOfFile(big.clusters, mapped, "clusters");
  expectViewOfFile(big.lod.indices, mapped, "hierarchy indices");
  expectViewOfFile(big.lod.clusters, mapped, "hierarchy clusters");
  expectViewOfFile(small.positions, mapped, "small positions");
  expectOwned(small.indices, "16-bit indices are widened into a vector");
  // The same scene as decoded from memory (copied), and the same file again when written.
  for (size_t i = 0; i < 2; ++i) {
    test::expectSameMesh(want.meshes[i], got.meshes[i]);
    EXPECT_EQ(want.meshes[i].lod.indices, got.meshes[i].lod.indices);
    ASSERT_EQ(want.meshes[i].lod.clusters.size(), got.meshes[i].lod.clusters.size());
    EXPECT_EQ(std::memcmp(want.meshes[i].lod.clusters.data(), got.meshes[i].lod.clusters.data(),
                          want.meshes[i].lod.clusters.size() * sizeof(LodCluster)),
              0);
  }
  EXPECT_EQ(encodeRtrScene(got), bytes);
  // Bytes with no owner to keep them (decoded from memory) are copied.
  const Scene copied = decodeRtrScene(span(bytes), "mem.rtrscene");
  expectOwned(copied.meshes[0].positions, "positions");
  expectOwned(copied.meshes[0].indices, "indices");
  expectOwned(copied.meshes[0].clusters, "clusters");
  expectOwned(copied.meshes[0].lod.clusters, "hierarchy clusters");
  EXPECT_EQ(encodeRtrScene(copied), bytes);
}

TEST(RtrSceneViews, TheMappingOutlivesTheSceneAndItsFile) {
  const Scene want = twoGrids();
  Mesh kept;
  {
    const TempFile file(encodeRtrScene(want));
    Scene got = loadRtrScene(file.path);
    ASSERT_TRUE(got.meshes[0].positions.isView());
    kept = got.meshes[0];  // shares the mapping, copies nothing
    EXPECT_EQ(kept.positions.data(), got.meshes[0].positions.data());
  }  // the scene and the file are gone; the mapping is not
  ASSERT_TRUE(kept.positions.isView());
  test::expectSameMesh(want.meshes[0], kept);
  EXPECT_EQ(want.meshes[0].lod.indices, kept.lod.indices);
}

TEST(RtrSceneViews, ChangingALoadedSceneCopiesWhatItChangesOnce) {
  const Scene want = twoGrids();
  const std::string bytes = encodeRtrScene(want);
  const TempFile file(bytes);
  Scene viewed = loadRtrScene(file.path), copied = decodeRtrScene(span(bytes), "mem.rtrscene");
  const glm::vec3* before = viewed.meshes[0].positions.data();
  for (Scene* s : {&viewed, &copied}) {
    turnScene(*s, upRotation("+Z"));
    buildClusters(s->meshes[1], true);  // reorders the indices
    generateTangents(s->meshes[0], s->meshes[0].texcoords);
  }
  const Mesh& m = viewed.meshes[0];
  expectOwned(m.positions, "positions");
  expectOwned(m.normals, "normals");
  expectOwned(m.tangents, "tangents");
  expectOwned(m.clusters, "clusters");
  EXPECT_NE(m.positions.data(), before);
  EXPECT_TRUE(m.texcoords.isView()) << "not changed: still a view";
  for (size_t i = 0; i < 2; ++i) test::expectSameMesh(copied.meshes[i], viewed.meshes[i]);
  EXPECT_EQ(encodeRtrScene(viewed), encodeRtrScene(copied));
  // The file and a new load of it are as they were.
  test::expectSameScene(want, loadRtrScene(file.path));
}

TEST(ViewOrVector, WritesToAViewCopyItAndLetTheOwnerGo) {
  auto held = std::make_shared<std::vector<int>>(std::vector<int>{1, 2, 3});
  ViewOrVector<int> v = ViewOrVector<int>::view(*held, held);
  EXPECT_EQ(held.use_count(), 2);
  v.push_back(v[0]);  // an element of the view, copied before the view goes
  EXPECT_FALSE(v.isView());
  EXPECT_EQ(held.use_count(), 1);
  EXPECT_EQ(v, (ViewOrVector<int>{1, 2, 3, 1}));
  EXPECT_EQ(*held, (std::vector<int>{1, 2, 3}));
  v = ViewOrVector<int>::view(*held, held);
  v.insert(v.begin() + 1, {7, 8});
  EXPECT_EQ(v, (ViewOrVector<int>{1, 7, 8, 2, 3}));
  v = ViewOrVector<int>::view(*held, held);
  v.clear();
  EXPECT_TRUE(v.empty());
  EXPECT_EQ(held.use_count(), 1);
  EXPECT_EQ(*held, (std::vector<int>{1, 2, 3}));
}

// Copying from its own view: the owner (here one that "unmaps", overwriting the bytes, when let go) must
// outlive the copy, though the array lets it go once it owns its elements.
TEST(ViewOrVector, CopiesFromItsOwnViewBeforeLettingTheOwnerGo) {
  std::vector<int> mapped;
  auto mapping = [&mapped] {
    mapped = {1, 2, 3};
    return std::shared_ptr<const void>(&mapped, [](const void* p) {
      auto* m = static_cast<std::vector<int>*>(const_cast<void*>(p));
      std::fill(m->begin(), m->end(), -1);
    });
  };
  ViewOrVector<int> a = ViewOrVector<int>::view(mapped, mapping());
  a.emplace_back(a[0]);
  EXPECT_EQ(a, (ViewOrVector<int>{1, 2, 3, 1}));
  a = ViewOrVector<int>::view(mapped, mapping());
  a.insert(a.end(), a.begin(), a.begin() + 2);
  EXPECT_EQ(a, (ViewOrVector<int>{1, 2, 3, 1, 2}));
  a = ViewOrVector<int>::view(mapped, mapping());
  a.assign(a.begin() + 1, a.end());
  EXPECT_EQ(a, (ViewOrVector<int>{2, 3}));
  EXPECT_EQ(mapped, (std::vector<int>{-1, -1, -1})) << "the owner is let go once the array owns its elements";
}

}  // namespace
}  // namespace rtr
