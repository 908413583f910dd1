// scenegen: writes the default scene, a temple courtyard standing in for Sun Temple (which cannot be
// shipped): zstd OBJ + MTL with the Sun Temple keys + generated PNGs of every PNG type and odd sizes.
// --scale N refines the tessellation for benchmarks (N = 100 gives about 1.6M vertices).
// --instances N also bakes temple-grid.rtrscene: N instances of the temple in a grid (rtr-bake's work,
// cluster hierarchy included; each mesh stored once, placed N times).
// --sphere-grid FILE.gltf writes only the metallic x roughness sphere grid (sphere_grid.hpp) instead.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <vector>

#include <CLI/CLI.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include "bake.hpp"
#include "core/atomic_file.hpp"
#include "core/cli.hpp"
#include "core/error.hpp"
#include "scene/rtrscene.hpp"
#include "objwriter.hpp"
#include "png.hpp"
#include "sphere_grid.hpp"

namespace fs = std::filesystem;
using scenegen::ObjWriter;

namespace {

// Deterministic value noise, so regenerated textures are byte-identical.
float hash2(int x, int y) {
  uint32_t h = uint32_t(x) * 374761393u + uint32_t(y) * 668265263u;
  h = (h ^ (h >> 13)) * 1274126177u;
  return float((h ^ (h >> 16)) & 0xFFFF) / 65535.0f;
}

using Pattern = std::function<float(float u, float v)>;

std::vector<uint8_t> image(int w, int h, int channels, const std::function<void(int, int, uint8_t*)>& px) {
  std::vector<uint8_t> out(size_t(w) * h * channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) px(x, y, &out[(size_t(y) * w + x) * channels]);
  return out;
}

uint8_t q(float v) { return uint8_t(std::lround(std::fmin(std::fmax(v, 0.0f), 1.0f) * 255.0f)); }

void writeTextures(const fs::path& dir) {
  fs::create_directories(dir);
  // floor: RGB tiles; roughness: 8-bit grey; normal map: RGB bumps.
  scenegen::writePng8(dir / "floor_col.png", 120, 90, 3, image(120, 90, 3, [](int x, int y, uint8_t* p) {
                        bool grout = x % 40 < 2 || y % 30 < 2;
                        float n = 0.85f + 0.15f * hash2(x / 3, y / 3);
                        p[0] = q(grout ? 0.35f : 0.78f * n);
                        p[1] = q(grout ? 0.33f : 0.70f * n);
                        p[2] = q(grout ? 0.3f : 0.58f * n);
                      }));
  scenegen::writePng8(dir / "floor_rough.png", 100, 75, 1,
                      image(100, 75, 1, [](int x, int y, uint8_t* p) { p[0] = q(0.55f + 0.4f * hash2(x / 4, y / 4)); }));
  scenegen::writePng8(dir / "floor_norm.png", 96, 72, 3, image(96, 72, 3, [](int x, int y, uint8_t* p) {
                        float nx = 0.25f * std::sin(x * 0.26f), ny = 0.25f * std::cos(y * 0.35f);
                        p[0] = q(nx * 0.5f + 0.5f);
                        p[1] = q(ny * 0.5f + 0.5f);
                        p[2] = q(0.5f + 0.5f * std::sqrt(1 - nx * nx - ny * ny));
                      }));
  // column: palette base colour (stone bands), 1-bit roughness.
  std::vector<uint8_t> pal;
  for (int i = 0; i < 16; ++i) pal.insert(pal.end(), {q(0.6f + 0.02f * i), q(0.56f + 0.02f * i), q(0.5f + 0.015f * i)});
  scenegen::writePalettePng(
      dir / "column_col.png", 72, 130,
      image(72, 130, 1,
            [](int x, int y, uint8_t* p) {
              p[0] = uint8_t((int(8 + 7 * std::sin(y * 0.2f + x * 0.02f)) + int(hash2(x / 2, y / 5) * 3)) % 16);
            }),
      pal);
  scenegen::writeBitPng(dir / "column_rough.png", 64, 100,
                        image(64, 100, 1, [](int x, int y, uint8_t* p) { p[0] = hash2(x / 8, y / 8) > 0.3f; }));
  scenegen::writeBitPng(dir / "wall_rough.png", 37, 23,
                        image(37, 23, 1, [](int x, int y, uint8_t* p) { p[0] = (x + y) % 5 != 0; }));
  scenegen::writePng8(dir / "wall_col.png", 160, 100, 3, image(160, 100, 3, [](int x, int y, uint8_t* p) {
                        int row = y / 20;
                        bool mortar = y % 20 < 2 || (x + (row % 2) * 20) % 40 < 2;
                        float n = 0.8f + 0.2f * hash2(x / 5 + row * 17, y / 5);
                        p[0] = q(mortar ? 0.5f : 0.72f * n);
                        p[1] = q(mortar ? 0.48f : 0.55f * n);
                        p[2] = q(mortar ? 0.45f : 0.42f * n);
                      }));
  // metals: an all-one metalness map (grey), gold base colour (RGB), shields (palette + 1-bit metalness).
  scenegen::writePng8(dir / "metal_full.png", 17, 13, 1, std::vector<uint8_t>(17 * 13, 255));
  scenegen::writePng8(dir / "gold_col.png", 50, 50, 3, image(50, 50, 3, [](int x, int y, uint8_t* p) {
                        float n = 0.9f + 0.1f * hash2(x / 2, y / 2);
                        p[0] = q(1.0f * n);
                        p[1] = q(0.77f * n);
                        p[2] = q(0.34f * n);
                      }));
  std::vector<uint8_t> shieldPal = {200, 160, 60, 150, 40, 30, 90, 90, 100, 230, 210, 150};
  scenegen::writePalettePng(dir / "shield_col.png", 90, 90,
                            image(90, 90, 1,
                                  [](int x, int y, uint8_t* p) {
                                    float r = std::hypot(x - 44.5f, y - 44.5f);
                                    p[0] = r < 8 ? 3 : r < 30 ? 1 : r < 38 ? 0 : 2;
                                  }),
                            shieldPal);
  scenegen::writeBitPng(dir / "shield_metal.png", 33, 33, image(33, 33, 1, [](int x, int y, uint8_t* p) {
                          float r = std::hypot(x - 16.0f, y - 16.0f);
                          p[0] = r < 3 || r > 11;
                        }));
  // foliage: RGBA leaves with cut-outs (base colour and alpha mask are the same file).
  scenegen::writePng8(dir / "leaves.png", 110, 140, 4, image(110, 140, 4, [](int x, int y, uint8_t* p) {
                        float u = (x + 0.5f) / 110, v = (y + 0.5f) / 140;
                        float leaf = std::fabs(std::sin(v * 18.0f + u * 3.0f)) * (1.0f - std::fabs(u - 0.5f) * 1.6f) - v * 0.25f;
                        p[0] = q(0.15f + 0.2f * hash2(x / 3, y / 3));
                        p[1] = q(0.45f + 0.3f * leaf);
                        p[2] = q(0.1f);
                        p[3] = leaf > 0.2f ? 255 : 0;
                      }));
  // fire: RGB base colour, RGBA emissive.
  scenegen::writePng8(dir / "fire_col.png", 40, 60, 3, image(40, 60, 3, [](int x, int y, uint8_t* p) {
                        p[0] = q(0.3f + 0.1f * hash2(x, y));
                        p[1] = q(0.15f);
                        p[2] = q(0.08f);
                      }));
  scenegen::writePng8(dir / "fire_emit.png", 48, 80, 4, image(48, 80, 4, [](int x, int y, uint8_t* p) {
                        float heat = std::fmax(0.0f, 1.0f - std::hypot(x - 23.5f, (y - 40.0f) * 0.6f) / 24.0f) *
                                     (0.7f + 0.3f * hash2(x / 2, y / 2));
                        p[0] = q(heat * 1.5f);
                        p[1] = q(heat * heat);
                        p[2] = q(heat * heat * heat * 0.5f);
                        p[3] = 255;
                      }));
}

void writeMtl(const fs::path& file) {
  std::ofstream m(file);
  m << "# Temple courtyard materials (Sun Temple keys: map_Kd map_Pr map_Pm map_d norm map_Ke; Kd Pr Pm)\n";
  auto mat = [&](const char* name, const char* body) {
    m << "\nnewmtl " << name << "\nNs 250\nKa 1 1 1\nKs 0.5 0.5 0.5\nNi 1.45\nd 1\nillum 2\n" << body;
  };
  mat("floor",
      "Kd 0.8 0.8 0.8\nPr 1\nPm 0\nmap_Kd textures/floor_col.png\nmap_Pr textures/floor_rough.png\nnorm textures/floor_norm.png\n");
  mat("steps", "Kd 0.9 0.85 0.8\nPr 1\nPm 0\nmap_Kd textures/floor_col.png\nmap_Pr textures/floor_rough.png\n");
  mat("wall", "Kd 1 1 1\nPr 1\nPm 0\nmap_Kd textures/wall_col.png\nmap_Pr textures/wall_rough.png\n");
  mat("column", "Kd 1 1 1\nPr 1\nPm 0\nmap_Kd textures/column_col.png\nmap_Pr textures/column_rough.png\n");
  mat("statue_gold", "Kd 1 0.77 0.34\nPr 0.3\nPm 1\nmap_Kd textures/gold_col.png\nmap_Pm textures/metal_full.png\n");
  mat("shield", "Kd 1 1 1\nPr 0.4\nPm 1\nmap_Kd textures/shield_col.png\nmap_Pm textures/shield_metal.png\n");
  mat("leaves.DoubleSided", "Kd 1 1 1\nPr 1\nPm 0\nmap_Kd textures/leaves.png\nmap_d textures/leaves.png\n");
  mat("ivy.DoubleSided", "Kd 0.7 0.9 0.6\nPr 1\nPm 0\nmap_Kd textures/leaves.png\nmap_d textures/leaves.png\n");
  mat("firepit_stone", "Kd 0.6 0.6 0.6\nPr 1\nPm 0\nmap_Kd textures/column_col.png\nmap_Pr textures/column_rough.png\n");
  mat("firepit_fire", "Kd 1 1 1\nKe 4 2 0.6\nPr 1\nPm 0\nmap_Kd textures/fire_col.png\nmap_Ke textures/fire_emit.png\n");
  mat("mirror", "Kd 0.95 0.95 0.95\nPr 0.02\nPm 1\nN_mirr 1\n");
}

// Smooth value noise in [0, 1): bilinear between lattice hashes `cell` texels apart.
float smoothNoise(float x, float y, float cell, int seed) {
  const float fx = x / cell, fy = y / cell;
  const int ix = int(std::floor(fx)), iy = int(std::floor(fy));
  const float tx = fx - float(ix), ty = fy - float(iy);
  auto h = [&](int a, int b) { return hash2(a + seed * 7919, b - seed * 104729); };
  const float top = h(ix, iy) + tx * (h(ix + 1, iy) - h(ix, iy));
  const float bottom = h(ix, iy + 1) + tx * (h(ix + 1, iy + 1) - h(ix, iy + 1));
  return top + ty * (bottom - top);
}

// --textures N: N RGB textures of 1024², like a real set's (compressible: tiles, smooth noise and a tint
// per texture, not random bytes), a material each and a gallery of N panels, one per material.
void writeTextureSet(const fs::path& dir, int count, ObjWriter& o, std::ofstream& mtl) {
  const int size = 1024;
  for (int i = 0; i < count; ++i) {
    const std::string name = "set_" + std::to_string(i);
    const int tile = 64 << (i % 3);
    const float tint[3] = {0.55f + 0.4f * hash2(i, 1), 0.5f + 0.4f * hash2(i, 2), 0.45f + 0.4f * hash2(i, 3)};
    scenegen::writePng8(dir / (name + ".png"), size, size, 3, image(size, size, 3, [&](int x, int y, uint8_t* p) {
                          const bool grout = x % tile < 3 || y % tile < 3;
                          const float n = 0.55f * smoothNoise(float(x), float(y), 96.0f, i) +
                                          0.3f * smoothNoise(float(x), float(y), 13.0f, i + 1000);
                          for (int c = 0; c < 3; ++c) p[c] = q(grout ? 0.3f : tint[c] * (0.45f + n));
                        }));
    mtl << "\nnewmtl " << name << "\nKd 1 1 1\nPr 0.8\nPm 0\nmap_Kd textures/" << name << ".png\n";
    // Panels on a wall behind the courtyard, 20 to a row.
    o.object("panel_" + std::to_string(i), name);
    const float x = -12.0f + 1.2f * float(i % 20), y = 0.2f + 1.2f * float(i / 20);
    o.grid({x, y, -26.0f}, {1.0f, 0, 0}, {0, 1.0f, 0}, 1, 1, {1, 1});
  }
}

// The temple baked (textures into temple-grid-tex/), then placed `count` times in a square grid, one
// instance per (cell, mesh), each cell a temple's width and a margin from the next.
void bakeGrid(const fs::path& dir, const fs::path& obj, int count) {
  const fs::path out = dir / "temple-grid.rtrscene";
  rtr::BakeOptions bo;
  bo.input = obj;
  bo.output = out;
  bo.force = true;
  bo.view = rtr::CameraPose{{0, 2.2f, -2.5f}, 0, -3};
  rtr::bake(bo);
  rtr::Scene s = rtr::loadRtrScene(out);
  const rtr::Bounds b = s.bounds();
  const glm::vec3 step = b.max - b.min + glm::vec3(4.0f);
  const int cols = int(std::ceil(std::sqrt(double(count))));
  for (int i = 0; i < count; ++i)
    for (uint32_t m = 0; m < s.meshes.size(); ++m)
      s.instances.push_back({m, glm::translate(glm::mat4(1.0f), glm::vec3(step.x * (i % cols), 0, -step.z * (i / cols)))});
  rtr::writeFileAtomic(out, rtr::encodeRtrScene(s));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Generates the temple courtyard scene (zstd OBJ + MTL + PNG textures)", "scenegen"};
  std::string out = "assets-src/temple";
  double scale = 1;
  bool plain = false;
  int textures = 0;
  app.add_option("--out", out, "output folder");
  app.add_option("--textures", textures, "also N textures of 1024x1024 on N panels (a real scene's texture set)")
      ->check(rtr::cli::integer(0, 10000));
  app.add_option("--scale", scale, "tessellation factor (100: about 1.6M vertices)")->check(rtr::cli::number(0.05, 10000.0));
  app.add_flag("--plain", plain, "write temple.obj instead of temple.obj.zst");
  int instances = 0;
  app.add_option("--instances", instances, "also bake temple-grid.rtrscene: N instances of the temple in a grid")
      ->check(rtr::cli::integer(0, 1000000));
  std::string sphereGrid;
  int gridSize = 5;
  app.add_option("--sphere-grid", sphereGrid,
                 "write only a glTF grid of spheres (metallic by row, roughness by column) to FILE.gltf (+ .bin)");
  app.add_option("--sphere-grid-size", gridSize, "spheres a side of --sphere-grid")->check(rtr::cli::integer(2, 16));
  if (const int rc = rtr::cli::parse(app, argc, argv); rc >= 0) return rc;
  try {
    if (!sphereGrid.empty()) {
      const fs::path file = sphereGrid;
      if (file.has_parent_path()) fs::create_directories(file.parent_path());
      scenegen::writeSphereGrid(file, gridSize);
      std::printf("wrote %s: %d x %d spheres\n", sphereGrid.c_str(), gridSize, gridSize);
      return 0;
    }
    const fs::path dir = out;
    if (dir.empty()) throw rtr::UsageError("--out: empty folder name");
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir)) throw rtr::Error(out + ": cannot create the output folder" + (ec ? ": " + ec.message() : ""));
    writeTextures(dir / "textures");
    writeMtl(dir / "temple.mtl");
    const float r = float(std::sqrt(scale));
    auto n = [&](int base) { return std::max(1, int(std::lround(base * r))); };
    ObjWriter o(dir / (plain ? "temple.obj" : "temple.obj.zst"), scale > 4 ? 3 : 19);
    o.line("# Temple courtyard (generated by tools/scenegen, scale " + std::to_string(scale) + ")");
    o.line("mtllib temple.mtl");
    o.object("floor", "floor");
    o.grid({-12, 0, 0}, {24, 0, 0}, {0, 0, -24}, n(24), n(24), {12, 12});
    o.object("walls", "wall");
    o.box({-12.5f, 0, -24}, {-12, 4, 0}, 0.5f);
    o.box({12, 0, -24}, {12.5f, 4, 0}, 0.5f);
    o.box({-12.5f, 0, -24.5f}, {12.5f, 4, -24}, 0.5f);
    o.object("steps", "steps");
    for (int s = 0; s < 3; ++s) o.box({-4.0f + s * 0.5f, 0, -24.0f}, {4.0f - s * 0.5f, 0.3f * (s + 1), -21.0f + s * 0.8f}, 1.0f);
    for (int side = -1; side <= 1; side += 2)
      for (int k = 0; k < 5; ++k) {
        o.object(std::string("column_") + (side < 0 ? "L" : "R") + std::to_string(k), "column");
        o.cylinder({side * 8.0f, 0, -4.0f - 4.0f * k}, 0.45f, 5.0f, n(24), n(6));
      }
    o.object("plinth", "wall");
    o.box({-0.7f, 0, -12.7f}, {0.7f, 1.0f, -11.3f}, 1.0f);
    o.object("statue", "statue_gold");
    o.blob({0, 2.2f, -12}, {0.55f, 1.2f, 0.5f}, n(48), n(64), 0.12f);
    o.object("shields", "shield");
    for (int side = -1; side <= 1; side += 2)
      for (int k = 0; k < 3; ++k) o.disc({side * 11.95f, 2.5f, -6.0f - 6.0f * k}, {-float(side), 0, 0}, 0.6f, 48);
    o.object("foliage", "leaves.DoubleSided");
    for (int k = 0; k < 10; ++k) o.cards({(k % 2 ? 1 : -1) * 7.2f, 0, -4.0f - 4.0f * (k / 2)}, 1.2f, 1.1f, 0.4f * k);
    o.object("ivy", "ivy.DoubleSided");
    for (int k = 0; k < 6; ++k) o.cards({-10.0f + 4.0f * k, 0, -23.5f}, 1.6f, 2.0f, 0.1f);
    for (int side = -1; side <= 1; side += 2) {
      glm::vec3 c(side * 3.5f, 0, -8.0f);
      o.object(std::string("firepit_") + (side < 0 ? "L" : "R"), "firepit_stone");
      o.box(c + glm::vec3(-0.6f, 0, -0.6f), c + glm::vec3(0.6f, 0.5f, -0.45f), 1);
      o.box(c + glm::vec3(-0.6f, 0, 0.45f), c + glm::vec3(0.6f, 0.5f, 0.6f), 1);
      o.box(c + glm::vec3(-0.6f, 0, -0.45f), c + glm::vec3(-0.45f, 0.5f, 0.45f), 1);
      o.box(c + glm::vec3(0.45f, 0, -0.45f), c + glm::vec3(0.6f, 0.5f, 0.45f), 1);
      o.object(std::string("fire_") + (side < 0 ? "L" : "R"), "firepit_fire");
      o.disc(c + glm::vec3(0, 0.4f, 0), {0, 1, 0}, 0.45f, 24);
      o.cards(c + glm::vec3(0, 0.4f, 0), 0.8f, 0.9f, 0.3f);
    }
    o.object("mirror", "mirror");
    o.grid({-2, 1.2f, -23.95f}, {4, 0, 0}, {0, 2.5f, 0}, 1, 1, {1, 1});
    if (textures > 0) {
      std::ofstream mtl(dir / "temple.mtl", std::ios::app);
      writeTextureSet(dir / "textures", textures, o, mtl);
    }
    o.finish();
    std::printf("wrote %s: %zu OBJ vertices (v records)\n", dir.c_str(), o.vertices());
    if (instances > 0) {
      bakeGrid(dir, dir / (plain ? "temple.obj" : "temple.obj.zst"), instances);
      std::printf("wrote %s: %d instances of the temple\n", (dir / "temple-grid.rtrscene").c_str(), instances);
    }
  } catch (const std::exception& e) { return rtr::cli::fail("scenegen", e); }
}
