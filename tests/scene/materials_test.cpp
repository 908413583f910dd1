// Polygon triangulation, classic MTL onto the PBR material, and the checker shown for broken textures.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "scene/load.hpp"
#include "scene/mtl.hpp"
#include "scene/obj.hpp"
#include "scene/textures.hpp"
#include "scene/triangulate.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using namespace rtr;
using ::testing::HasSubstr;
using Tris = std::vector<std::array<uint32_t, 3>>;

namespace {

glm::vec3 newell(const std::vector<glm::vec3>& p) {
  glm::vec3 n(0.0f);
  for (size_t i = 0; i < p.size(); ++i) n += glm::cross(p[i], p[(i + 1) % p.size()]);
  return n;  // twice the vector area
}

// Winding number of q about the polygon p (both in the z = 0 plane).
int winding(const std::vector<glm::vec3>& p, glm::vec3 q) {
  int w = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    glm::vec3 a = p[i], b = p[(i + 1) % p.size()];
    const float side = (b.x - a.x) * (q.y - a.y) - (q.x - a.x) * (b.y - a.y);
    if (a.y <= q.y && b.y > q.y && side > 0) ++w;
    if (a.y > q.y && b.y <= q.y && side < 0) --w;
  }
  return w;
}

// The triangles cover the polygon exactly: the same vector area, every triangle wound like the polygon
// and inside it.
void expectCovers(const std::vector<glm::vec3>& poly, const Tris& tris, bool planeZ) {
  glm::vec3 sum(0.0f);
  const glm::vec3 n = newell(poly);
  for (const auto& t : tris) {
    const glm::vec3 a = poly[t[0]], b = poly[t[1]], c = poly[t[2]];
    const glm::vec3 tn = glm::cross(b - a, c - a);
    EXPECT_GT(glm::dot(tn, n), 0.0f) << "triangle " << t[0] << "," << t[1] << "," << t[2] << " flipped or flat";
    sum += tn;
    if (planeZ) {
      EXPECT_NE(winding(poly, (a + b + c) / 3.0f), 0) << "triangle " << t[0] << "," << t[1] << "," << t[2] << " outside";
    }
  }
  EXPECT_NEAR(glm::length(sum - n), 0.0f, 1e-4f * glm::length(n));
}

Tris triangulate(const std::vector<glm::vec3>& p, bool* ok = nullptr) {
  Tris t;
  const bool r = triangulatePolygon(p, t);
  if (ok) *ok = r;
  return t;
}

MtlMaterial mtl(const std::string& text) {
  auto ms = parseMtl(text, "t.mtl", [](const std::string&) {});
  EXPECT_EQ(ms.size(), 1u);
  return ms.at(0);
}

}  // namespace

TEST(Triangulate, ConvexPolygonsKeepTheFan) {
  // A pentagon, and a square with a corner in the middle of an edge: the course's fan, as before.
  const std::vector<glm::vec3> penta{{0, 0, 0}, {2, 0, 0}, {3, 1, 0}, {1, 3, 0}, {-1, 1, 0}};
  EXPECT_EQ(triangulate(penta), (Tris{{0, 1, 2}, {0, 2, 3}, {0, 3, 4}}));
  const std::vector<glm::vec3> square{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}};
  EXPECT_EQ(triangulate(square), (Tris{{0, 1, 2}, {0, 2, 3}, {0, 3, 4}}));
}

TEST(Triangulate, ConcavePolygonsAreEarClipped) {
  // An L (reflex corner at 3): the fan from corner 0 would cover the missing square.
  const std::vector<glm::vec3> l{{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
  expectCovers(l, triangulate(l), true);
  // The same L wound the other way.
  std::vector<glm::vec3> lr(l.rbegin(), l.rend());
  expectCovers(lr, triangulate(lr), true);
  // A U with collinear corners along its bottom and sides, starting at a reflex corner.
  const std::vector<glm::vec3> u{{2, 3, 0}, {2, 1, 0},    {1, 1, 0}, {1, 3, 0}, {0, 3, 0}, {0, 1.5f, 0},
                                 {0, 0, 0}, {1.5f, 0, 0}, {3, 0, 0}, {4, 0, 0}, {4, 3, 0}, {3, 3, 0}};
  const Tris tu = triangulate(u);
  expectCovers(u, tu, true);
  // A dart (concave quad) in a tilted plane: projected on the Newell normal's plane.
  const std::vector<glm::vec3> dart{{0, 0, 0}, {2, 1, 2}, {0, 0.5f, 0.5f}, {-2, 1, 2}};
  const Tris td = triangulate(dart);
  EXPECT_EQ(td.size(), 2u);
  expectCovers(dart, td, false);
}

TEST(Triangulate, SelfIntersectingPolygonReportsIt) {
  bool ok = true;
  // Its edge 4-0 crosses edges 1-2 and 2-3; ear clipping gets stuck, the rest is a fan.
  const Tris t = triangulate({{4, 1, 0}, {4, 4, 0}, {1, 3, 0}, {0, 3, 0}, {2, 4, 0}}, &ok);
  EXPECT_FALSE(ok);
  EXPECT_FALSE(t.empty());
}

TEST(Triangulate, AssimpConcavePolygonKeepsItsArea) {
  const fs::path f = "/usr/share/assimp/models/OBJ/concave_polygon.obj";
  if (!fs::is_regular_file(f)) GTEST_SKIP() << "assimp-testmodels is not installed";
  // The polygon as written: its vertices in face order.
  std::vector<glm::vec3> v, poly;
  std::ifstream in(f);
  for (std::string line; std::getline(in, line);) {
    std::istringstream ls(line);
    std::string k;
    ls >> k;
    if (k == "v") {
      glm::vec3 p;
      ls >> p.x >> p.y >> p.z;
      v.push_back(p);
    }
    if (k == "f")
      for (std::string c; ls >> c;) poly.push_back(v.at(std::stoul(c) - 1));
  }
  ASSERT_GT(poly.size(), 40u);
  LoadOptions o;
  o.note = o.warn = [](const std::string& w) { ADD_FAILURE() << w; };
  const Scene s = loadScene(f, o);
  ASSERT_EQ(s.meshes.size(), 1u);
  const Mesh& m = s.meshes[0];
  // A fan's signed areas add up to the polygon's too; the unsigned ones only when nothing overlaps or flips.
  const float area = glm::length(newell(poly));
  float unsignedSum = 0.0f;
  for (uint32_t i = 0; i < m.indices.size(); i += 3) {
    const glm::vec3 a = m.positions[m.indices[i]], b = m.positions[m.indices[i + 1]], c = m.positions[m.indices[i + 2]];
    EXPECT_GT(glm::dot(glm::cross(b - a, c - a), newell(poly)), 0.0f) << "triangle " << i / 3 << " flipped";
    unsignedSum += glm::length(glm::cross(b - a, c - a));
  }
  EXPECT_NEAR(unsignedSum, area, 1e-4f * area);
}

TEST(Triangulate, ObjReaderWarnsAboutSelfIntersectingFaces) {
  std::vector<std::string> warnings;
  ObjOptions o;
  o.warn = [&](const std::string& w) { warnings.push_back(w); };
  auto src = memorySource("v 4 1 0\nv 4 4 0\nv 1 3 0\nv 0 3 0\nv 2 4 0\nf 1 2 3 4 5\n", "t.obj");
  parseObj(
      *src, "t.obj", [](const std::string&) { return std::nullopt; }, o);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_THAT(warnings[0], HasSubstr("t.obj:6: polygon of 5 corners crosses itself"));
}

TEST(ClassicMtl, RoughnessFromNsWhenNoPr) {
  // Beckmann alpha = roughness^2 (shaders/shared/brdf.h brdfAlpha) = sqrt(2 / (Ns + 2)).
  for (float ns : {0.0f, 1.0f, 10.0f, 98.0f, 400.0f, 1000.0f}) {
    const float r = mtl("newmtl a\nNs " + std::to_string(ns) + "\n").material.roughness;
    EXPECT_NEAR(r * r, std::sqrt(2.0f / (ns + 2.0f)), 1e-6f) << ns;
  }
  EXPECT_FLOAT_EQ(mtl("newmtl a\nPr 0.3\nNs 98\n").material.roughness, 0.3f);
  EXPECT_FLOAT_EQ(mtl("newmtl a\nNs 98\nPr 0.3\n").material.roughness, 0.3f);
  EXPECT_FLOAT_EQ(mtl("newmtl a\nKd 1 1 1\n").material.roughness, 1.0f);
  EXPECT_FLOAT_EQ(mtl("newmtl a\nNs -5\n").material.roughness, 1.0f);
  EXPECT_FLOAT_EQ(mtl("newmtl a\nNs 98\n").material.metalness, 0.0f);
}

TEST(ClassicMtl, BlackKdWithATextureShowsTheTexture) {
  MtlMaterial m = mtl("newmtl a\nKd 0 0 0\nmap_Kd a.png\n");
  EXPECT_EQ(m.material.baseColor, glm::vec3(1.0f));
  EXPECT_EQ(m.material.kd, glm::vec3(0.0f));  // the Phong tracer's Kd is kept as written
  EXPECT_EQ(mtl("newmtl a\nKd 0 0 0\n").material.baseColor, glm::vec3(0.0f));
  EXPECT_EQ(mtl("newmtl a\nKd 0.5 0.5 0.5\nmap_Kd a.png\n").material.baseColor, glm::vec3(0.5f));
}

TEST(ClassicMtl, DissolveAndTransparencyAreRecorded) {
  EXPECT_FLOAT_EQ(mtl("newmtl a\nd 0.25\n").material.transparency, 0.75f);
  EXPECT_FLOAT_EQ(mtl("newmtl a\nTr 0.4\n").material.transparency, 0.4f);
  EXPECT_FLOAT_EQ(mtl("newmtl a\nillum 2\nmap_Ks s.png\nmap_bump b.png\nbump b.png\n").material.transparency, 0.0f);
}

TEST(TextureFallback, Checker) {
  const TexelData c = fallbackTexels(4);
  ASSERT_EQ(c.texels.size(), size_t(c.width) * c.height * 4);
  auto px = [&](uint32_t x, uint32_t y) {
    const uint8_t* p = &c.texels[(size_t(y) * c.width + x) * 4];
    return std::array<int, 4>{p[0], p[1], p[2], p[3]};
  };
  EXPECT_EQ(px(0, 0), (std::array<int, 4>{255, 0, 255, 255}));
  EXPECT_EQ(px(8, 0), (std::array<int, 4>{0, 0, 0, 255}));
  EXPECT_EQ(px(8, 8), px(0, 0));
  const TexelData g = fallbackTexels(1);
  EXPECT_EQ(g.texels.at(0), 255);
  EXPECT_EQ(g.texels.at(8), 0);
}

TEST(TextureFallback, MissingAndBrokenTexturesDecodeToTheChecker) {
  const fs::path dir = fs::temp_directory_path() / ("rtr_tex_fallback_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "junk.png") << "not an image";
  fs::copy_file(rtr::test::sourceDir() / "assets-src/temple/textures/gold_col.png", dir / "good.png",
                fs::copy_options::overwrite_existing);
  Scene s;
  s.baseDir = dir;
  s.textures = {{"missing.png", true, 4}, {"junk.png", false, 1}, {"good.png", true, 4}};
  std::vector<TexelData> got(3);
  std::vector<std::string> warnings;
  std::mutex mu;
  const uint32_t which[] = {0, 1, 2};
  decodeTextures(
      s, which, [&](size_t i, TexelData&& t) { got[i] = std::move(t); },
      [&](const std::string& w) {
        const std::lock_guard l(mu);
        warnings.push_back(w);
      });
  EXPECT_EQ(got[0].texels, fallbackTexels(4).texels);
  EXPECT_EQ(got[1].texels, fallbackTexels(1).texels);
  EXPECT_NE(got[2].texels, fallbackTexels(4).texels);
  EXPECT_GT(got[2].width, 0u);
  ASSERT_EQ(warnings.size(), 2u);
  std::sort(warnings.begin(), warnings.end());
  EXPECT_THAT(warnings[0], HasSubstr((dir / "junk.png").string() + ": cannot decode image"));
  EXPECT_THAT(warnings[1], HasSubstr((dir / "missing.png").string() + ": texture file does not exist"));
  fs::remove_all(dir);
}
