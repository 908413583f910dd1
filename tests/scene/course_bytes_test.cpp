// An independent byte-level reading of the .comp5892mesh that rtr-bake writes, straight from the
// docs/formats.md table (it shares no code with the writer or the reader in src/scene).
#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "bake.hpp"
#include "scene/load.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;

namespace {

struct Cursor {
  std::vector<uint8_t> d;
  size_t p = 0;
  uint32_t u32() {
    EXPECT_LE(p + 4, d.size());
    uint32_t v = uint32_t(d[p]) | uint32_t(d[p + 1]) << 8 | uint32_t(d[p + 2]) << 16 | uint32_t(d[p + 3]) << 24;
    p += 4;
    return v;
  }
  uint8_t u8() { return d.at(p++); }
  float f32() {
    uint32_t u = u32();
    float f;
    std::memcpy(&f, &u, 4);
    return f;
  }
};

fs::path tempDir(const char* tag) {
  fs::path d = fs::temp_directory_path() / (std::string("rtr_") + tag + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

}  // namespace

TEST(CourseBytes, TempleBakeFollowsTheTable) {
  const fs::path dir = tempDir("course_bytes");
  rtr::BakeOptions o;
  o.input = rtr::test::sourceDir() / "assets-src/temple/temple.obj.zst";
  o.output = dir / "temple.comp5892mesh";
  o.threads = 2;
  rtr::bake(o);
  std::ifstream in(o.output, std::ios::binary);
  Cursor c{std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {})};

  const uint8_t magic[16] = {0, 0, 'C', 'O', 'M', 'P', '5', '8', '9', '2', 'M', 'm', 'e', 's', 'h', 0};
  ASSERT_EQ(std::memcmp(c.d.data(), magic, 16), 0);
  const uint8_t variant[16] = {'d', 'e', 'f', 'a', 'u', 'l', 't', '-', 'a', '1', '2', 0, 0, 0, 0, 0};
  ASSERT_EQ(std::memcmp(c.d.data() + 16, variant, 16), 0);
  c.p = 32;

  const uint32_t T = c.u32();
  std::vector<std::string> paths;
  std::vector<std::pair<int, int>> formats;  // colour space, channels
  for (uint32_t t = 0; t < T; ++t) {
    const uint32_t n = c.u32();
    ASSERT_GT(n, 1u);
    ASSERT_LT(n, 32768u);
    ASSERT_EQ(c.d.at(c.p + n - 1), 0) << "string must count and end in its NUL";
    paths.emplace_back(reinterpret_cast<const char*>(&c.d[c.p]), n - 1);
    c.p += n;
    int cs = c.u8(), ch = c.u8();
    formats.emplace_back(cs, ch);
    EXPECT_EQ(paths.back().rfind("temple-tex/", 0), 0u) << paths.back();
    EXPECT_TRUE(fs::is_regular_file(dir / paths.back())) << paths.back();
  }
  // 14 source textures and three fallbacks.
  EXPECT_EQ(T, 17u);
  for (size_t i = 0; i < paths.size(); ++i)
    for (size_t j = i + 1; j < paths.size(); ++j) EXPECT_NE(paths[i], paths[j]);

  const uint32_t M = c.u32();
  EXPECT_EQ(M, 11u);  // every MTL material, in MTL order
  const std::pair<int, int> slotFormat[6] = {{1, 4}, {0, 1}, {0, 1}, {1, 4}, {0, 3}, {1, 4}};
  uint32_t nextNew = 0;
  for (uint32_t m = 0; m < M; ++m)
    for (int s = 0; s < 6; ++s) {
      const uint32_t id = c.u32();
      if (id == 0xFFFFFFFFu) {
        EXPECT_TRUE(s == 3 || s == 4) << "only alphaMask and normalMap may be absent";
        continue;
      }
      ASSERT_LT(id, T);
      EXPECT_LE(id, nextNew) << "ids are given at first appearance";
      if (id == nextNew) {
        ++nextNew;
        EXPECT_EQ(formats[id], slotFormat[s]) << paths[id];
      }
    }
  EXPECT_EQ(nextNew, T);

  // The course format stores no clusters, so the baker leaves the indices in the order the OBJ gave them.
  const rtr::Scene src = rtr::loadObj(o.input);
  const uint32_t meshes = c.u32();
  ASSERT_EQ(meshes, src.meshes.size());
  for (uint32_t i = 0; i < meshes; ++i) {
    const uint32_t mat = c.u32(), V = c.u32(), I = c.u32();
    EXPECT_EQ(mat, src.meshes[i].material);
    ASSERT_EQ(V, src.meshes[i].positions.size());
    ASSERT_EQ(I, src.meshes[i].indices.size());
    ASSERT_LE(c.p + size_t(V) * 32 + size_t(I) * 4, c.d.size());
    for (uint32_t v = 0; v < V; ++v)
      for (int k = 0; k < 3; ++k) ASSERT_EQ(c.f32(), src.meshes[i].positions[v][k]);
    for (uint32_t v = 0; v < V; ++v)
      for (int k = 0; k < 3; ++k) ASSERT_EQ(c.f32(), src.meshes[i].normals[v][k]);
    for (uint32_t v = 0; v < V; ++v)
      for (int k = 0; k < 2; ++k) ASSERT_EQ(c.f32(), src.meshes[i].texcoords.empty() ? 0.0f : src.meshes[i].texcoords[v][k]);
    for (uint32_t k = 0; k < I; ++k) ASSERT_EQ(c.u32(), src.meshes[i].indices[k]);
  }
  EXPECT_EQ(c.p, c.d.size()) << "a correct file ends right after the last mesh";
  fs::remove_all(dir);
}
