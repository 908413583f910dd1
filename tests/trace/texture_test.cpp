// Textures in the tracer's PBR mode: texel values, trilinear filtering with ray-cone LOD, REPEAT, alpha
// masks for primary, mirror and shadow rays, and errors for bad texture files.
#include <array>
#include <cmath>
#include <fstream>
#include <functional>

#include <unistd.h>

#include <gtest/gtest.h>
#include <glm/trigonometric.hpp>

#include "core/error.hpp"
#include "core/mip_reference.hpp"
#include "trace/procedural.hpp"
#include "trace/textures.hpp"
#include "trace/tracer.hpp"

namespace rtr::trace {
namespace {

using Texel = std::array<uint8_t, 4>;

std::filesystem::path tempDir() {
  const auto d = std::filesystem::temp_directory_path() / ("rtr_texture_test_" + std::to_string(getpid()));
  std::filesystem::create_directories(d);
  return d;
}

// Writes a w×h RGBA PNG (row 0: v = 0 side) and adds it to the scene; returns its texture index.
uint32_t addTexture(Scene& s, const std::string& name, uint32_t w, uint32_t h,
                    const std::function<Texel(uint32_t, uint32_t)>& texel, bool srgb = true, uint8_t channels = 4) {
  ImageRGBA8 img{w, h, std::vector<uint8_t>(size_t(w) * h * 4)};
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) std::copy_n(texel(x, y).begin(), 4, img.at(x, y));
  const auto path = tempDir() / (name + ".png");
  savePng(path, img);
  s.textures.push_back({path, srgb, channels});
  return uint32_t(s.textures.size() - 1);
}

Material pbr(glm::vec3 base, uint32_t baseTexture = kNoTexture) {
  Material m;
  m.baseColor = base;
  m.textures[uint32_t(TextureSlot::BaseColor)] = baseTexture;
  return m;
}

// PBR with no light and ambient 1: a pixel is exactly the surface's base colour (brdf.h: ambient · base).
TraceSettings baseColourView() {
  TraceSettings ts;
  ts.shading = Shading::Pbr;
  ts.shadows = false;
  ts.bounces = 0;
  ts.lights = LightRig{{}, glm::vec3(1.0f), {}};  // no light, ambient 1
  ts.height = 32768;                              // a tiny pixel: level 0 unless a test says otherwise
  return ts;
}

// A 2×2 quad at z = -depth facing +z, uv = ((x + 1) / 2, (y + 1) / 2) scaled by `uvScale`.
Mesh facingQuad(float depth, uint32_t material, float uvScale = 1.0f) {
  Mesh m = quad({-1, -1, -depth}, {2, 0, 0}, {0, 2, 0}, material);
  for (glm::vec2& t : m.texcoords.writable()) t *= uvScale;
  return m;
}

// The ray straight down -z onto texture coordinate uv of facingQuad(uvScale 1) from distance `dist`.
Ray rayAt(glm::vec2 uv, float depth, float dist) { return {{2.0f * uv.x - 1.0f, 2.0f * uv.y - 1.0f, dist - depth}, {0, 0, -1}}; }

float srgb(uint8_t b) { return float(decodeTexel(b, 0, TexelEncoding::Srgb)); }

// A 4×4 texture of distinct colours.
Texel pattern(uint32_t x, uint32_t y) { return {uint8_t(40 + 60 * x), uint8_t(200 - 50 * y), uint8_t(17 * (x + 4 * y)), 255}; }

void expectNear(glm::vec3 a, glm::vec3 b, float tol, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, tol) << what;
  EXPECT_NEAR(a.y, b.y, tol) << what;
  EXPECT_NEAR(a.z, b.z, tol) << what;
}

TEST(TracerTextures, TexelCentresGiveDecodedTexelTimesFactor) {
  Scene s;
  const glm::vec3 factor{0.5f, 1.0f, 0.8f};
  addMesh(s, facingQuad(2, addMaterial(s, pbr(factor, addTexture(s, "pattern", 4, 4, pattern)))));
  const Tracer t(s);
  const TraceSettings ts = baseColourView();
  for (uint32_t y = 0; y < 4; ++y)
    for (uint32_t x = 0; x < 4; ++x) {
      const Texel p = pattern(x, y);
      const glm::vec3 want = factor * glm::vec3(srgb(p[0]), srgb(p[1]), srgb(p[2]));
      expectNear(t.traceAndShade(rayAt({(x + 0.5f) / 4, (y + 0.5f) / 4}, 2, 1), 0, ts), want, 1e-5f,
                 "texel " + std::to_string(x) + "," + std::to_string(y));
    }
  // Half way between two texel centres: the mean of the *decoded* values (sRGB decodes before filtering).
  const Texel a = pattern(1, 2), b = pattern(2, 2);
  const glm::vec3 mid = t.traceAndShade(rayAt({0.5f, 2.5f / 4}, 2, 1), 0, ts);
  EXPECT_NEAR(mid.x, factor.x * 0.5f * (srgb(a[0]) + srgb(b[0])), 1e-5f);
  EXPECT_GT(std::abs(mid.x - factor.x * srgb(uint8_t((a[0] + b[0]) / 2))), 1e-3f);
  EXPECT_EQ(t.textures().count(), 1u);
}

TEST(TracerTextures, RepeatWrapsCoordinatesOutsideZeroOne) {
  Scene s;
  Mesh m = facingQuad(2, addMaterial(s, pbr(glm::vec3(1), addTexture(s, "pattern", 4, 4, pattern))), 3.0f);
  for (glm::vec2& uv : m.texcoords.writable()) uv -= glm::vec2(1.0f);  // uv in [-1, 2]
  addMesh(s, std::move(m));
  const Tracer t(s);
  const TraceSettings ts = baseColourView();
  // World point (x, y) has uv = 1.5·(x + 1) - 1; the same texel every whole period.
  auto at = [&](float u, float v) { return t.traceAndShade({{(u + 1) / 1.5f - 1, (v + 1) / 1.5f - 1, 0}, {0, 0, -1}}, 0, ts); };
  const Texel p = pattern(1, 3);
  const glm::vec3 texel{srgb(p[0]), srgb(p[1]), srgb(p[2])};
  for (glm::vec2 uv : {glm::vec2(0.375f, 0.875f), glm::vec2(-0.625f, -0.125f), glm::vec2(1.375f, 1.875f)})
    expectNear(at(uv.x, uv.y), texel, 1e-5f, "uv " + std::to_string(uv.x) + "," + std::to_string(uv.y));
  // On the seam u = 0 (u = 1) the filter mixes the last and the first column (CLAMP would not).
  const Texel l = pattern(3, 1), r = pattern(0, 1);
  EXPECT_NEAR(at(0.0f, 0.375f).x, 0.5f * (srgb(l[0]) + srgb(r[0])), 1e-4f);
  EXPECT_NEAR(at(1.0f, 0.375f).x, 0.5f * (srgb(l[0]) + srgb(r[0])), 1e-4f);
}

// An 8×8 one-texel checker: level 1 and every level above are uniform grey, so the ray-cone LOD can be
// read off the contrast: λ = log2(uv per scene unit · cone width / |n·d| · 8).
TEST(TracerTextures, RayConeLodFollowsDistancePixelSizeAndProjection) {
  Scene s;
  const auto checker = [](uint32_t x, uint32_t y) {
    const uint8_t c = (x + y) % 2 ? 255 : 0;
    return Texel{c, c, c, 255};
  };
  addMesh(s, facingQuad(0, addMaterial(s, pbr(glm::vec3(1), addTexture(s, "checker", 8, 8, checker)))));
  const Tracer t(s);
  TraceSettings ts = baseColourView();
  ts.height = 100;
  const float spread = std::atan(2.0f * std::tan(glm::radians(ts.lens.fovYDeg) * 0.5f) / 100.0f);
  const glm::vec2 white{1.5f / 8, 0.5f / 8};
  const float grey = float(decodeTexel(encodeTexel(0.5, 0, TexelEncoding::Srgb), 0, TexelEncoding::Srgb));
  // uv per scene unit is 1/2, so λ = log2(spread · dist · 4): λ = 0.5 at dist = √2 / (4 · spread).
  auto whiteAt = [&](float lod) { return t.traceAndShade(rayAt(white, 0, std::exp2(lod) / (4 * spread)), 0, ts).x; };
  EXPECT_NEAR(whiteAt(-1.0f), 1.0f, 1e-5f);
  EXPECT_NEAR(whiteAt(0.5f), 0.5f + 0.5f * grey, 1e-4f);
  EXPECT_NEAR(whiteAt(1.0f), grey, 1e-4f);
  EXPECT_NEAR(whiteAt(20.0f), grey, 1e-5f);  // far beyond the 1×1 level: clamped to it
  ts.lodBias = 1.0f;                         // the GPU's LOD bias: one level up
  EXPECT_NEAR(whiteAt(-0.5f), 0.5f + 0.5f * grey, 1e-4f);
  ts.lodBias = 0.0f;
  float previous = 2.0f;
  for (float lod = -1.0f; lod <= 1.5f; lod += 0.125f) {
    const float v = whiteAt(lod);
    EXPECT_LE(v, previous + 1e-6f) << "LOD must rise with distance (λ " << lod << ")";
    previous = v;
  }
  // Seen at 60° from the normal the footprint is twice as long: one level up at the same distance.
  const float dist = std::exp2(-0.5f) / (4 * spread);
  const glm::vec3 d = glm::normalize(glm::vec3(std::sin(glm::radians(60.0f)), 0.0f, -0.5f));
  const glm::vec3 hit{2 * white.x - 1, 2 * white.y - 1, 0};
  EXPECT_NEAR(t.traceAndShade({hit - d * dist, d}, 0, ts).x, 0.5f + 0.5f * grey, 1e-3f);
  // Orthographic: a constant width 2h/H, whatever the distance (here λ = log2(0.5 · 2h/H · 8) = 1).
  ts.lens.orthographic = true;
  ts.lens.orthoHalfHeight = 25.0f;
  for (float dist : {0.5f, 50.0f}) EXPECT_NEAR(t.traceAndShade(rayAt(white, 0, dist), 0, ts).x, grey, 1e-4f);
}

TEST(TracerTextures, FarAwayGivesTheChainsOneTexelAverage) {
  Scene s;
  addMesh(s, facingQuad(0, addMaterial(s, pbr(glm::vec3(1), addTexture(s, "pattern", 4, 4, pattern)))));
  const Tracer t(s);
  TraceSettings ts = baseColourView();
  ts.height = 10;
  TexelData img{4, 4, 4, {}};
  for (uint32_t y = 0; y < 4; ++y)
    for (uint32_t x = 0; x < 4; ++x) {
      const Texel p = pattern(x, y);
      img.texels.insert(img.texels.end(), p.begin(), p.end());
    }
  const MipChain chain = buildMipReference(img, TexelEncoding::Srgb, MipSource::PreviousLevel);
  const std::vector<uint8_t> top = quantizeMipLevel(chain, 2);
  ASSERT_EQ(top.size(), 4u);
  const glm::vec3 c = t.traceAndShade(rayAt({0.3f, 0.7f}, 0, 1000.0f), 0, ts);
  expectNear(c, {srgb(top[0]), srgb(top[1]), srgb(top[2])}, 1e-5f, "1×1 level");
}

TEST(TracerTextures, FetchMultipliesEverySlotLikeTheGpu) {
  Scene s;
  Material m = pbr({0.5f, 0.25f, 1.0f}, addTexture(s, "base", 1, 1, [](uint32_t, uint32_t) { return Texel{255, 128, 64, 255}; }));
  m.roughness = 0.5f;
  m.metalness = 0.8f;
  m.emissive = {2, 3, 4};
  const auto grey = [](uint8_t v) { return [v](uint32_t, uint32_t) { return Texel{v, v, v, 255}; }; };
  m.textures[uint32_t(TextureSlot::Roughness)] = addTexture(s, "rough", 1, 1, grey(51), false, 1);
  m.textures[uint32_t(TextureSlot::Metalness)] = addTexture(s, "metal", 1, 1, grey(102), false, 1);
  m.textures[uint32_t(TextureSlot::AlphaMask)] = addTexture(
      s, "alpha", 1, 1,
      [](uint32_t, uint32_t) {
        return Texel{0, 0, 0, 77};
      },
      true, 4);
  m.textures[uint32_t(TextureSlot::Emissive)] = addTexture(s, "emit", 1, 1, grey(128));
  m.textures[uint32_t(TextureSlot::NormalMap)] = uint32_t(s.textures.size());  // never read: a missing file
  s.textures.push_back({"/nonexistent/normal.png", false, 3});
  addMesh(s, facingQuad(0, addMaterial(s, m)));
  const SceneTextures tex(s);
  EXPECT_EQ(tex.count(), 5u);
  const SurfaceInputs in = tex.fetch(s.materials[0], {{0.3f, 0.6f}}, 0.0f);
  expectNear(in.baseColor, {0.5f * srgb(255), 0.25f * srgb(128), srgb(64)}, 1e-6f, "base");
  EXPECT_NEAR(in.roughness, 0.5f * 51 / 255.0f, 1e-6f);  // UNORM, not sRGB
  EXPECT_NEAR(in.metalness, 0.8f * 102 / 255.0f, 1e-6f);
  EXPECT_NEAR(in.alpha, 77 / 255.0f, 1e-6f);  // alpha is never sRGB
  expectNear(in.emissive, glm::vec3(2, 3, 4) * srgb(128), 1e-5f, "emissive");
}

// The texture cache (scene/texture_cache.hpp) gives the tracer back the very chains it made: the second
// load takes every texture from it and every sample is the same.
TEST(TracerTextures, ChainsFromTheTextureCacheSampleAsDecodedOnes) {
  const auto dir = tempDir() / "cache";
  std::filesystem::remove_all(dir);
  Scene s;
  Material m = pbr(glm::vec3(1.0f), addTexture(s, "noise", 37, 23, [](uint32_t x, uint32_t y) {
                     return Texel{uint8_t(x * 7 + y * 13), uint8_t(x * y), uint8_t(255 - x), uint8_t(y * 11)};
                   }));
  m.textures[uint32_t(TextureSlot::Roughness)] = addTexture(
      s, "grey", 19, 40,
      [](uint32_t x, uint32_t y) {
        return Texel{uint8_t(x * 13 ^ y * 5), 0, 0, 255};
      },
      false, 1);
  addMesh(s, facingQuad(0, addMaterial(s, m)));
  TextureCache cache(dir, uint64_t(1) << 30);
  const SceneTextures plain(s), first(s, &cache), second(s, &cache);
  EXPECT_EQ(first.cacheHits(), 0u);
  EXPECT_EQ(second.cacheHits(), 2u);
  EXPECT_EQ(cache.counts().stored, 2u);
  for (TextureSlot slot : {TextureSlot::BaseColor, TextureSlot::Roughness})
    for (float lod : {0.0f, 0.7f, 1.5f, 2.2f, 4.0f, 9.0f})
      for (float u = -0.3f; u < 1.3f; u += 0.0731f)
        for (float v = -0.2f; v < 1.2f; v += 0.0917f) {
          const float width = std::exp2(lod) / std::sqrt(37.0f * 23.0f);
          const glm::vec4 want = plain.sample(s.materials[0], slot, {{u, v}}, width, glm::vec4(-1));
          EXPECT_EQ(first.sample(s.materials[0], slot, {{u, v}}, width, glm::vec4(-1)), want);
          ASSERT_EQ(second.sample(s.materials[0], slot, {{u, v}}, width, glm::vec4(-1)), want) << u << " " << v << " " << lod;
        }
  std::filesystem::remove_all(dir);
}

// A red quad at z = -2 whose left half (u < 0.5) is cut out by its mask, in front of a blue one at z = -4.
Scene maskedPair() {
  Scene s;
  Material red = pbr({1, 0, 0});
  red.flags = kMaterialAlphaMasked | kMaterialDoubleSided;
  red.textures[uint32_t(TextureSlot::AlphaMask)] = addTexture(s, "half", 8, 1, [](uint32_t x, uint32_t) {
    return Texel{255, 255, 255, uint8_t(x < 4 ? 0 : 255)};
  });
  addMesh(s, facingQuad(2, addMaterial(s, red)));
  Mesh floor = quad({-6, -6, -4}, {12, 0, 0}, {0, 12, 0}, addMaterial(s, pbr({0, 0, 1})));
  addMesh(s, std::move(floor));
  return s;
}

TEST(TracerTextures, AlphaMaskLetsPrimaryAndMirrorRaysThroughExactlyWhereCut) {
  Scene s = maskedPair();
  // Off to the side (y < -7): a 45° mirror turns rays going down -z to +y, onto the same masked material
  // facing -y at y = -8 (u along x, v = 0.5 where the rays cross it) with blue behind it at y = -7.
  Material mirror = pbr(glm::vec3(0.2f));
  mirror.mirror = 1.0f;
  addMesh(s, quad({-1, -11, 0}, {2, 0, 0}, {0, 2, -2}, addMaterial(s, mirror)));  // plane y + z = -11
  addMesh(s, quad({-1, -8, 0}, {2, 0, 0}, {0, 0, -2}, 0));                        // masked, y = -8
  addMesh(s, quad({-6, -7, 6}, {12, 0, 0}, {0, 0, -12}, 1));                      // blue, y = -7
  const Tracer t(s);
  const TraceSettings ts = baseColourView();
  int cut = 0, kept = 0;
  for (float u = 0.05f; u < 1.0f; u += 0.1f) {
    const glm::vec3 want = u < 0.5f ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0);
    (u < 0.5f ? cut : kept)++;
    expectNear(t.traceAndShade(rayAt({u, 0.5f}, 2, 3), 0, ts), want, 1e-6f, "primary, u " + std::to_string(u));
    // Down -z onto the mirror at y = -10, z = -1, reflected to +y: through the masked quad at u.
    const Ray toMirror{{2 * u - 1, -10, 5}, {0, 0, -1}};
    expectNear(t.traceAndShade(toMirror, 1, ts), want, 1e-6f, "mirror, u " + std::to_string(u));
  }
  EXPECT_EQ(cut, 5);
  EXPECT_EQ(kept, 5);
  ImageF img;
  TraceSettings rs = baseColourView();
  rs.width = rs.height = 16;
  rs.pose = CameraPose{{0, 0, 3}, 0, 0};
  EXPECT_GT(t.render(rs, img).alphaRays, 0u);
}

TEST(TracerTextures, CutOutTexelsCastNoShadow) {
  const Scene s = maskedPair();
  const Tracer t(s);
  TraceSettings ts = baseColourView();
  Light light;
  light.position = {0, 0, 10};
  ts.lights = LightRig{{light}, glm::vec3(0.1f), {}};
  ts.shadows = true;
  // Floor points seen from between the quads; their shadow rays to the light cross the masked quad at
  // 12/14 of their distance from the axis.
  for (float xa : {-0.75f, -0.25f, 0.25f, 0.75f}) {
    const Ray r{{xa * 14 / 12, 0.1f, -3}, {0, 0, -1}};
    ts.shadows = true;
    const glm::vec3 on = t.traceAndShade(r, 0, ts);
    ts.shadows = false;
    const glm::vec3 off = t.traceAndShade(r, 0, ts);
    if (xa < 0) expectNear(on, off, 0.0f, "cut-out part must not shadow, x " + std::to_string(xa));
    else expectNear(on, glm::vec3(0, 0, 0.1f), 1e-6f, "opaque part must shadow, x " + std::to_string(xa));
    EXPECT_GT(off.z, 0.2f);
  }
}

TEST(TracerTextures, AlphaLayersAreBounded) {
  Scene s;
  Material clear = pbr({0, 1, 0});
  clear.flags = kMaterialAlphaMasked;
  clear.textures[uint32_t(TextureSlot::AlphaMask)] = addTexture(s, "clear", 1, 1, [](uint32_t, uint32_t) { return Texel{}; });
  const uint32_t m = addMaterial(s, clear);
  for (int i = 0; i < kMaxAlphaLayers + 4; ++i) addMesh(s, facingQuad(float(i + 1), m));
  const Tracer t(s);
  // Every layer is cut out; after kMaxAlphaLayers of them the next one is shown (green), not the background.
  const glm::vec3 c = t.traceAndShade(rayAt({0.3f, 0.6f}, 0, 1), 0, baseColourView());
  expectNear(c, {0, 1, 0}, 0.0f, "layer after the last allowed cut-out");
}

// A texture that is missing or does not decode is shown as the shared magenta/black checker, in pbr and
// in Phong (Kd x map_Kd), never as a silent white or an abort; the other views do not need it.
TEST(TracerTextures, BadFilesShowTheCheckerInPbrAndPhong) {
  const auto garbage = tempDir() / "garbage.png";
  std::ofstream(garbage) << "not a png";
  for (const std::filesystem::path& file : {std::filesystem::path("/nonexistent/missing_base.png"), garbage}) {
    Scene s;
    s.textures.push_back({file, true, 4});
    Material m = pbr(glm::vec3(1), 0);
    m.kd = glm::vec3(1);
    m.ka = m.ks = glm::vec3(0.0f);  // Phong: diffuse only, so a pixel is Kd x texture x n.l
    addMesh(s, facingQuad(2, addMaterial(s, m)));
    const Tracer t(s);
    TraceSettings ts = baseColourView();
    ts.width = ts.height = 8;
    ImageF img;
    for (Shading other : {Shading::Normals, Shading::Depth}) {
      ts.shading = other;
      EXPECT_NO_THROW(t.render(ts, img));
    }
    for (Shading shaded : {Shading::Pbr, Shading::Phong}) {
      ts.shading = shaded;
      if (shaded == Shading::Phong) ts.lights = resolveLights(s);  // a headlight: Kd lights up
      t.render(ts, img);
      int magenta = 0, green = 0;
      for (const glm::vec4& p : img.pixels) {
        magenta += p.r > 0.2f && p.b > 0.2f && p.g < 0.05f;
        green += p.g > 0.05f;
      }
      EXPECT_GT(magenta, 0) << file << " shading " << int(shaded);
      EXPECT_EQ(green, 0) << file << " shading " << int(shaded) << ": an untextured white surface";
    }
  }
}

}  // namespace
}  // namespace rtr::trace
