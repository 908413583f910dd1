// The tracer's glTF materials: the BRDF each material gets (shaders/shared/brdf.h) and its overrides;
// vertex colours, unlit, alpha MASK and BLEND, single-sided culling, texture transforms and the second uv
// set, normal maps and occlusion.
#include <array>
#include <cmath>
#include <functional>

#include <unistd.h>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "core/image.hpp"
#include "core/mip_reference.hpp"

#include "brdf.h"
#include "lights.h"
#include "trace/procedural.hpp"
#include "trace/tracer.hpp"

namespace rtr::trace {
namespace {

// Two quads side by side facing +z, x < 0 with an OBJ-like material, x > 0 with a glTF one, same factors.
Scene twoMaterials() {
  Scene s;
  Material m;
  m.baseColor = glm::vec3(0.8f, 0.6f, 0.4f);
  m.roughness = 0.35f;
  m.metalness = 0.4f;
  const uint32_t obj = addMaterial(s, m);
  m.flags = kMaterialGltf;
  const uint32_t gltf = addMaterial(s, m);
  addMesh(s, quad({-2, -1, 0}, {2, 0, 0}, {0, 2, 0}, obj));
  addMesh(s, quad({0, -1, 0}, {2, 0, 0}, {0, 2, 0}, gltf));
  return s;
}

TEST(GltfMaterial, GltfUsesGgxAndTheRestBeckmannUnlessOverridden) {
  const Scene s = twoMaterials();
  const Tracer t(s);
  TraceSettings ts;
  ts.shading = Shading::Pbr;
  ts.bounces = 0;
  Light l;
  l.position = {0.3f, 0.5f, 2.0f};
  ts.lights = LightRig{{l}, glm::vec3(0.0f), ""};
  const Ray left{{-0.5f, 0.2f, 3.0f}, glm::normalize(glm::vec3(-0.2f, -0.1f, -1.0f))};  // hits x = -1.1
  const Ray right{{1.5f, 0.2f, 3.0f}, glm::normalize(glm::vec3(-0.2f, -0.1f, -1.0f))};  // hits x = 0.9
  const glm::vec3 objDefault = t.traceAndShade(left, 0, ts), gltfDefault = t.traceAndShade(right, 0, ts);
  ts.brdf = Brdf::Ggx;
  const glm::vec3 objGgx = t.traceAndShade(left, 0, ts);
  EXPECT_EQ(t.traceAndShade(right, 0, ts), gltfDefault);
  ts.brdf = Brdf::Beckmann;
  EXPECT_EQ(t.traceAndShade(left, 0, ts), objDefault);
  const glm::vec3 gltfBeckmann = t.traceAndShade(right, 0, ts);
  // Each is the shared header's BRDF of that name at that point.
  const glm::vec3 v = -glm::normalize(left.direction);
  const SurfacePoint sp = t.surface(left, t.closestTriangle(left));
  const shader::LightSample ls = shader::lightSample(l.position, l.color, false, sp.position);
  const auto direct = [&](int brdf) {
    return shader::pbrDirect(brdf, sp.normal, v, ls.l, ls.radiance, glm::vec3(0.8f, 0.6f, 0.4f), 0.35f, 0.4f);
  };
  EXPECT_EQ(objDefault, direct(BRDF_BECKMANN));
  EXPECT_EQ(objGgx, direct(BRDF_GGX));
  EXPECT_NE(objDefault, objGgx);
  EXPECT_NE(gltfDefault, gltfBeckmann);
}

// No light, ambient 1: a pixel is ambient · base (· occlusion) + emissive (brdf.h), level-0 texels.
TraceSettings baseView() {
  TraceSettings ts;
  ts.shading = Shading::Pbr;
  ts.shadows = false;
  ts.bounces = 0;
  ts.lights = LightRig{{}, glm::vec3(1.0f), {}};
  ts.height = 32768;
  return ts;
}

Material gltf(glm::vec3 base, uint32_t flags = 0) {
  Material m;
  m.flags = kMaterialGltf | flags;
  m.baseColor = base;
  return m;
}

// A 2×2 quad at z = -depth facing +z (or -z: `back`), uv = ((x + 1) / 2, (y + 1) / 2).
Mesh facing(float depth, uint32_t material, bool back = false) {
  return back ? quad({-1, -1, -depth}, {0, 2, 0}, {2, 0, 0}, material) : quad({-1, -1, -depth}, {2, 0, 0}, {0, 2, 0}, material);
}

// Straight down -z from z = 0 onto quad point (x, y).
glm::vec3 at(const Tracer& t, const TraceSettings& ts, float x = 0.1f, float y = 0.2f) {
  return t.traceAndShade({{x, y, 0.0f}, {0, 0, -1}}, 0, ts);
}

void expectNear(glm::vec3 a, glm::vec3 b, const std::string& what, float tol = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, tol) << what;
  EXPECT_NEAR(a.y, b.y, tol) << what;
  EXPECT_NEAR(a.z, b.z, tol) << what;
}

// Vertex colours (glTF COLOR_0, OBJ `v x y z r g b`) multiply the base colour of every material, as on the GPU.
TEST(GltfMaterial, VertexColourMultipliesTheBaseColourOfEveryMaterial) {
  for (bool isGltf : {true, false}) {
    Scene s;
    Material m = gltf({0.5f, 1.0f, 0.8f});
    if (!isGltf) m.flags = 0;
    Mesh q = facing(2, addMaterial(s, m));
    q.colors.assign(q.positions.size(), glm::vec4(0.5f, 0.25f, 1.0f, 1.0f));
    addMesh(s, std::move(q));
    const Tracer t(s);
    expectNear(at(t, baseView()), glm::vec3(0.25f, 0.25f, 0.8f), isGltf ? "glTF" : "OBJ");
  }
}

TEST(GltfMaterial, UnlitShowsTheBaseColourWhateverTheLights) {
  Scene s;
  addMesh(s, facing(2, addMaterial(s, gltf({0.3f, 0.6f, 0.9f}, kMaterialUnlit))));
  const Tracer t(s);
  TraceSettings ts = baseView();
  Light l;
  l.position = {0.3f, 0.0f, 1.0f};
  l.color = glm::vec3(5.0f);
  ts.lights = LightRig{{l}, glm::vec3(0.3f), {}};
  for (Shading shading : {Shading::Pbr, Shading::Phong}) {
    ts.shading = shading;
    EXPECT_EQ(at(t, ts), glm::vec3(0.3f, 0.6f, 0.9f));
  }
}

// A front quad over a back quad: MASK cuts by opacity × vertex alpha against alphaCutoff.
TEST(GltfMaterial, MaskCutsOutBelowTheCutoff) {
  const glm::vec3 front(0.2f, 0.4f, 0.6f), back(0.9f, 0.1f, 0.1f);
  for (float opacity : {0.3f, 0.45f, 0.9f})
    for (float vertexAlpha : {1.0f, 0.5f}) {
      Scene s;
      Material m = gltf(front, kMaterialAlphaMasked);
      m.opacity = opacity;
      m.alphaCutoff = 0.4f;
      Mesh q = facing(2, addMaterial(s, m));
      q.colors.assign(q.positions.size(), glm::vec4(1.0f, 1.0f, 1.0f, vertexAlpha));
      addMesh(s, std::move(q));
      addMesh(s, facing(4, addMaterial(s, gltf(back))));
      const Tracer t(s);
      const bool cut = opacity * vertexAlpha < 0.4f;
      EXPECT_EQ(at(t, baseView()), cut ? back : front) << opacity << " " << vertexAlpha;
    }
}

TEST(GltfMaterial, BlendCompositesOverWhatLiesBeyond) {
  const glm::vec3 a(0.2f, 0.4f, 0.6f), b(0.9f, 0.3f, 0.1f), c(0.05f, 0.8f, 0.5f);
  Scene s;
  Material m = gltf(a, kMaterialBlend);
  m.opacity = 0.25f;
  addMesh(s, facing(2, addMaterial(s, m)));
  Material m2 = gltf(b, kMaterialBlend);
  m2.opacity = 0.5f;
  addMesh(s, facing(3, addMaterial(s, m2)));
  addMesh(s, facing(4, addMaterial(s, gltf(c))));
  const Tracer t(s);
  expectNear(at(t, baseView()), 0.25f * a + 0.75f * (0.5f * b + 0.5f * c), "two layers over an opaque one");
  TraceSettings bg = baseView();
  bg.background = glm::vec3(1.0f, 0.0f, 0.0f);
  expectNear(at(t, bg, 3.0f, 0.0f), bg.background, "beside the quads: the background");
}

TEST(GltfMaterial, SingleSidedBacksAreCulledDoubleSidedAndObjOnesShown) {
  const glm::vec3 front(0.2f, 0.4f, 0.6f), behind(0.9f, 0.1f, 0.1f);
  for (int kind = 0; kind < 3; ++kind) {  // single-sided glTF, double-sided glTF, OBJ
    Scene s;
    Material m = gltf(front, kind == 1 ? kMaterialDoubleSided : 0);
    if (kind == 2) m.flags = 0;
    addMesh(s, facing(2, addMaterial(s, m), /*back=*/true));
    addMesh(s, facing(4, addMaterial(s, gltf(behind))));
    const Tracer t(s);
    EXPECT_EQ(at(t, baseView()), kind == 0 ? behind : front) << kind;
  }
}

std::filesystem::path tempDir() {
  const auto d = std::filesystem::temp_directory_path() / ("rtr_gltf_material_test_" + std::to_string(getpid()));
  std::filesystem::create_directories(d);
  return d;
}

using Texel = std::array<uint8_t, 4>;
uint32_t addTexture(Scene& s, const std::string& name, uint32_t w, uint32_t h,
                    const std::function<Texel(uint32_t, uint32_t)>& texel, bool srgb, uint8_t channels) {
  ImageRGBA8 img{w, h, std::vector<uint8_t>(size_t(w) * h * 4)};
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) std::copy_n(texel(x, y).begin(), 4, img.at(x, y));
  const auto path = tempDir() / (name + ".png");
  savePng(path, img);
  s.textures.push_back({path, srgb, channels});
  return uint32_t(s.textures.size() - 1);
}

Texel pattern(uint32_t x, uint32_t y) { return {uint8_t(40 + 60 * x), uint8_t(200 - 50 * y), uint8_t(17 * (x + 4 * y)), 255}; }
glm::vec3 decoded(const Texel& p) {
  auto srgb = [](uint8_t b) { return float(decodeTexel(b, 0, TexelEncoding::Srgb)); };
  return {srgb(p[0]), srgb(p[1]), srgb(p[2])};
}

// KHR_texture_transform: uv' = offset + R (scale ⊙ uv), R = [cos sin; -sin cos] (counter-clockwise with v
// down), on the slot's uv set.
TEST(GltfMaterial, TextureTransformAndSecondUvSet) {
  for (uint32_t set : {0u, 1u}) {
    Scene s;
    Material m = gltf(glm::vec3(1.0f));
    m.textures[uint32_t(TextureSlot::BaseColor)] = addTexture(s, "pattern", 4, 4, pattern, true, 4);
    UvTransform& x = m.uv[uint32_t(TextureSlot::BaseColor)];
    x.offset = {0.25f, 0.5f};
    x.rotation = 0.3f;
    x.scale = {0.5f, 0.75f};
    x.texCoord = set;
    Mesh q = facing(2, addMaterial(s, m));
    q.texcoords1 = q.texcoords;
    // Set 0 is junk where set 1 is the one used; set 1 is the mirror of set 0.
    for (glm::vec2& t : (set == 1 ? q.texcoords1 : q.texcoords).writable()) t = glm::vec2(1.0f) - t;
    if (set == 1)
      for (glm::vec2& t : q.texcoords.writable()) t = glm::vec2(0.37f);
    addMesh(s, std::move(q));
    const Tracer t(s);
    for (glm::vec2 p : {glm::vec2(0.1f, 0.2f), glm::vec2(-0.6f, 0.7f), glm::vec2(0.5f, -0.3f)}) {
      const glm::vec2 uv = glm::vec2(1.0f) - (p + 1.0f) * 0.5f;
      const glm::vec2 sc = uv * x.scale;
      const float c = std::cos(x.rotation), sn = std::sin(x.rotation);
      glm::vec2 tuv = x.offset + glm::vec2(c * sc.x + sn * sc.y, -sn * sc.x + c * sc.y);
      tuv -= glm::floor(tuv);
      // Nearest texel centre of the expected uv: aim where the transformed uv is a texel centre instead.
      const glm::vec3 got = at(t, baseView(), p.x, p.y);
      // Bilinear at tuv from the 4×4 pattern (REPEAT), decoded then filtered.
      const float fx = tuv.x * 4 - 0.5f, fy = tuv.y * 4 - 0.5f;
      const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
      const float ax = fx - float(x0), ay = fy - float(y0);
      auto texel = [&](int i, int j) { return decoded(pattern(uint32_t((i + 4) % 4), uint32_t((j + 4) % 4))); };
      const glm::vec3 want = (1 - ay) * ((1 - ax) * texel(x0, y0) + ax * texel(x0 + 1, y0)) +
                             ay * ((1 - ax) * texel(x0, y0 + 1) + ax * texel(x0 + 1, y0 + 1));
      expectNear(got, want, "set " + std::to_string(set), 2e-4f);
    }
  }
}

// glTF samplers' wrap modes address the texels (at texel centres: exactly one texel).
TEST(GltfMaterial, SamplerWrapModes) {
  struct Case {
    Wrap wrap;
    float u;
    uint32_t texel;
  };
  for (const Case c : {Case{Wrap::Repeat, 1.375f, 1}, Case{Wrap::ClampToEdge, 1.375f, 3}, Case{Wrap::ClampToEdge, 1.875f, 3},
                       Case{Wrap::MirroredRepeat, 1.125f, 3}, Case{Wrap::MirroredRepeat, 1.375f, 2}}) {
    Scene s;
    Material m = gltf(glm::vec3(1.0f));
    m.textures[uint32_t(TextureSlot::BaseColor)] = addTexture(s, "pattern", 4, 4, pattern, true, 4);
    s.textures.back().sampler.wrapU = c.wrap;
    Mesh q = facing(2, addMaterial(s, m));
    for (glm::vec2& t : q.texcoords.writable()) t *= 2.0f;  // uv = (x + 1, y + 1)
    addMesh(s, std::move(q));
    const Tracer t(s);
    expectNear(at(t, baseView(), c.u - 1.0f, 0.375f - 1.0f), decoded(pattern(c.texel, 1)),
               "wrap " + std::to_string(int(c.wrap)) + " u " + std::to_string(c.u));
  }
}

float unorm(uint8_t b) { return float(decodeTexel(b, 0, TexelEncoding::Unorm)); }

// A uniform normal map on a quad with tangent +x: the shading normal is T·x + B·y + N·z of the texel's
// 2·v − 1 (x, y times normalScale), B = N × T = +y; without tangents the interpolated normal stays.
TEST(GltfMaterial, NormalMapTiltsTheShadingNormalOnTheTangentFrame) {
  const Texel texel{204, 110, 230, 255};
  for (int variant = 0; variant < 3; ++variant) {  // tangents; tangents with bitangent sign -1; none
    Scene s;
    Material m = gltf(glm::vec3(0.7f, 0.6f, 0.5f));
    m.roughness = 0.5f;
    m.normalScale = 0.7f;
    m.textures[uint32_t(TextureSlot::NormalMap)] = addTexture(
        s, "normal", 4, 4, [&](uint32_t, uint32_t) { return texel; }, false, 4);
    Mesh q = facing(2, addMaterial(s, m));
    if (variant < 2) q.tangents.assign(q.positions.size(), glm::vec4(1, 0, 0, variant == 0 ? 1.0f : -1.0f));
    addMesh(s, std::move(q));
    const Tracer t(s);
    TraceSettings ts = baseView();
    Light l;
    l.position = {1.0f, 0.5f, 1.0f};
    ts.lights = LightRig{{l}, glm::vec3(0.0f), {}};
    const glm::vec3 p(0.1f, 0.2f, -2.0f);
    const float sign = variant == 1 ? -1.0f : 1.0f;
    const glm::vec3 n = variant == 2
                            ? glm::vec3(0, 0, 1)
                            : glm::normalize(glm::vec3((2 * unorm(texel[0]) - 1) * 0.7f, sign * (2 * unorm(texel[1]) - 1) * 0.7f,
                                                       2 * unorm(texel[2]) - 1));
    const glm::vec3 want =
        shader::pbrDirect(BRDF_GGX, n, glm::vec3(0, 0, 1), glm::normalize(l.position - p), l.color, m.baseColor, 0.5f, 0.0f);
    expectNear(at(t, ts), want, "variant " + std::to_string(variant), 2e-5f);
  }
}

TEST(GltfMaterial, OcclusionScalesTheAmbientTermByItsStrength) {
  Scene s;
  Material m = gltf(glm::vec3(0.8f, 0.5f, 0.25f));
  m.occlusionStrength = 0.5f;
  m.textures[uint32_t(TextureSlot::Occlusion)] = addTexture(
      s, "occlusion", 4, 4,
      [](uint32_t, uint32_t) {
        return Texel{128, 128, 128, 255};
      },
      false, 1);
  addMesh(s, facing(2, addMaterial(s, m)));
  const Tracer t(s);
  const float ao = 1.0f + 0.5f * (unorm(128) - 1.0f);
  expectNear(at(t, baseView()), m.baseColor * ao, "ambient 1, no light");
}

}  // namespace
}  // namespace rtr::trace
