// Light from an environment in the shading passes (forward and visibility): the white furnace (a white
// sphere in uniform radiance 1 reflects at most all of it, and what the split sum says at normal
// incidence), a sun 10^5 times brighter than the sky (finite, no fireflies), no environment is the image of
// before, environment light shows a black model, and the debug views of its two terms sum to it. Lavapipe
// with validation: any message fails.
#include <cmath>
#include <cstdio>

#include <glm/gtc/matrix_inverse.hpp>

#include <gtest/gtest.h>

#include "brdf.h"
#include "core/bounds.hpp"
#include "core/camera.hpp"
#include "env_prefilter.h"
#include "render/environment_maps.hpp"
#include "render/headless.hpp"
#include "scene/clusters.hpp"
#include "vk_fixture.hpp"

namespace rtr {
namespace {

constexpr VkExtent2D kE{360, 150};
constexpr int kCols = 6;  // roughness 0, 0.2, ... 1
constexpr float kSpacing = 2.5f;
const glm::vec3 kMarker(-1.0f);  // the background colour: no shading writes a negative value

Mesh sphere(glm::vec3 centre, uint32_t material) {
  Mesh m;
  m.name = "sphere";
  m.material = material;
  const int rings = 48, segments = 96;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s <= segments; ++s) {
      const float th = float(M_PI) * float(r) / rings, ph = 2.0f * float(M_PI) * float(s) / segments;
      const glm::vec3 d(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
      m.positions.push_back(centre + d);
      m.normals.push_back(d);
    }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const uint32_t a = r * (segments + 1) + s, b = a + segments + 1;
      m.indices.insert(m.indices.end(), {a, a + 1, b, a + 1, b + 1, b});
    }
  for (const glm::vec3& p : m.positions) m.bounds.extend(p);
  buildClusters(m, true);
  return m;
}

glm::vec3 centreOf(int row, int col) { return {(col - 0.5f * (kCols - 1)) * kSpacing, (0.5f - row) * kSpacing, 0.0f}; }
float roughnessOf(int col) { return float(col) / float(kCols - 1); }

// Row 0 dielectric, row 1 metal (unless `metalRow` is false); roughness along each row; all of base colour `c`.
Scene sphereGrid(glm::vec3 c, bool metalRow = true) {
  Scene s;
  for (int row = 0; row < 2; ++row)
    for (int col = 0; col < kCols; ++col) {
      Material m;
      m.name = "m" + std::to_string(row) + std::to_string(col);
      m.baseColor = c;
      m.metalness = metalRow ? float(row) : 0.0f;
      m.roughness = roughnessOf(col);
      s.meshes.push_back(sphere(centreOf(row, col), uint32_t(s.materials.size())));
      s.materials.push_back(m);
    }
  return s;
}

ImageF uniformMap(float radiance) {
  return ImageF{64, 32, std::vector<glm::vec4>(64 * 32, glm::vec4(glm::vec3(radiance), 1.0f))};
}

// Sky of radiance 1 and one texel of 10^5 (the sun, 0.7 degrees wide, about 40 degrees up) in a 512 x 256
// map: 128² source faces, so its texel is small against the rough lobes' samples.
ImageF sunMap() {
  ImageF m{512, 256, std::vector<glm::vec4>(512 * 256, glm::vec4(1.0f))};
  m.at(320, 56) = glm::vec4(1e5f, 1e5f, 1e5f, 1.0f);
  return m;
}

struct View {
  CameraPose pose;
  Lens lens;
  glm::mat4 viewProj;
};

View gridView(const Scene& s) {
  const float aspect = float(kE.width) / float(kE.height);
  View v;
  v.pose = CameraPose{glm::vec3(0.0f, 0.0f, 11.0f), 0.0f, 0.0f};
  v.lens = fitDepthRange(Lens{}, s.bounds(), v.pose);
  v.viewProj = projectionMatrix(v.lens, aspect) * viewMatrix(v.pose);
  return v;
}

// The pixel a scene point projects to (Vulkan: y down).
glm::ivec2 pixelOf(const View& v, glm::vec3 p) {
  const glm::vec4 c = v.viewProj * glm::vec4(p, 1.0f);
  return {int((c.x / c.w * 0.5f + 0.5f) * kE.width), int((c.y / c.w * 0.5f + 0.5f) * kE.height)};
}

struct Path {
  render::ShadingPath shading;
  render::RasterPath raster;
};
std::vector<Path> paths() {
  return {{render::ShadingPath::Forward, render::RasterPath::Auto},
          {render::ShadingPath::Visibility, render::RasterPath::Hardware}};
}

render::RenderSettings envSettings(Path p, int brdf) {
  render::RenderSettings s;
  s.shading = p.shading;
  s.raster = p.raster;
  s.mosaic = render::MosaicMode::Off;
  s.lights = LightRig{{}, glm::vec3(0.0f), {}};  // the environment alone
  s.background = kMarker;
  s.backdropBlur = -1.0f;
  s.brdf = brdf;
  return s;
}

bool covered(const glm::vec4& p) { return p.r >= 0.0f; }

class EnvironmentShadingTest : public test::VulkanTest {};

// Where pixel (x, y)'s ray through its centre meets the grid's analytic spheres: the sphere (row * kCols +
// col) and n.v there; none: -1.
struct Hit {
  int sphere = -1;
  float nv = 0.0f;
};
Hit hitOf(const View& v, uint32_t x, uint32_t y) {
  const glm::mat4 inv = glm::inverse(v.viewProj);
  const glm::vec4 h = inv * glm::vec4(2.0f * (x + 0.5f) / kE.width - 1.0f, 2.0f * (y + 0.5f) / kE.height - 1.0f, 0.5f, 1.0f);
  const glm::vec3 o = v.pose.position, d = glm::normalize(glm::vec3(h) / h.w - o);
  Hit best;
  float bestT = 1e30f;
  for (int i = 0; i < 2 * kCols; ++i) {
    const glm::vec3 oc = o - centreOf(i / kCols, i % kCols);
    const float b = glm::dot(oc, d), disc = b * b - (glm::dot(oc, oc) - 1.0f);
    if (disc < 0.0f || -b - std::sqrt(disc) >= bestT) continue;
    bestT = -b - std::sqrt(disc);
    best = {i, glm::dot(glm::normalize(oc + bestT * d), -d)};
  }
  return best;
}

// The white furnace: white spheres (metal 0 and 1, roughness 0..1) in uniform radiance 1, lit by nothing
// else. Each pixel is the BRDF's directional albedo at its n.v (the split sum with the table evaluated on
// the CPU, prefiltered radiance 1, irradiance pi), so the energy lost at high roughness (Beckmann's single
// scattering) is measured, not hidden, and GGX's compensated for (a white GGX metal reflects 1); metals
// reflect at most 1 + eps everywhere (eps: the table's half floats). The dielectrics do not: brdf.h's
// diffuse keeps (1 - F(v.h)) of its light per light direction while the specular takes almost all of it at
// grazing view (docs/environment.md); the test states that bound.
TEST_F(EnvironmentShadingTest, WhiteFurnaceReflectsAtMostWhatComesIn) {
  const Scene scene = sphereGrid(glm::vec3(1.0f));
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  render::HeadlessRenderer r(*ctx, gpu, kE);
  const auto maps = std::make_shared<const render::EnvironmentMaps>(*ctx, Environment(uniformMap(1.0f), 1.0f, 0.0f));
  r.renderer().setEnvironment(maps);
  const View v = gridView(scene);
  std::vector<Hit> hits;
  for (uint32_t y = 0; y < kE.height; ++y)
    for (uint32_t x = 0; x < kE.width; ++x) hits.push_back(hitOf(v, x, y));
  for (int brdf : {BRDF_GGX, BRDF_BECKMANN})
    for (const Path& p : paths()) {
      SCOPED_TRACE(testing::Message() << (brdf == BRDF_GGX ? "ggx, " : "beckmann, ") << enumName(p.shading));
      const ImageF img = r.render(v.pose, v.lens, envSettings(p, brdf), 1, true).sceneColor;
      size_t n = 0, off = 0;
      float metalMax = 0.0f, dielectricMax = 0.0f, worstErr = 0.0f, worstGgxMetal = 0.0f;
      size_t ggxMetalOff = 0;
      for (size_t i = 0; i < img.pixels.size(); ++i) {
        const glm::vec4 px = img.pixels[i];
        if (!covered(px)) continue;
        ++n;
        const Hit h = hits[i];
        ASSERT_GE(h.sphere, 0) << "pixel " << i << " covered off every sphere";
        const int row = h.sphere / kCols;
        const float value = std::max({px.r, px.g, px.b});
        (row ? metalMax : dielectricMax) = std::max(row ? metalMax : dielectricMax, value);
        if (h.nv < 0.15f) continue;  // the silhouette: the mesh's normals are not the sphere's there
        const glm::vec3 abc = shader::envBrdfLut(brdf, h.nv, roughnessOf(h.sphere % kCols), 1024);
        const float want =
            shader::envSplitSum(brdf, glm::vec3(shader::BRDF_PI), glm::vec3(1.0f), abc, glm::vec3(1.0f), float(row)).g;
        worstErr = std::max(worstErr, std::abs(px.g - want));
        off += std::abs(px.g - want) > 0.03f;
        // GGX's multiple-scattering compensation: a white metal reflects all the light at every roughness
        // (single scattering: 0.32 at roughness 1), known without the table.
        if (brdf == BRDF_GGX && row == 1) {
          worstGgxMetal = std::max(worstGgxMetal, std::abs(px.g - 1.0f));
          ggxMetalOff += std::abs(px.g - 1.0f) > 0.01f;
        }
      }
      EXPECT_GT(n, img.pixels.size() / 20);
      EXPECT_EQ(off, 0u) << "pixels off the BRDF's albedo by more than 0.03 (worst " << worstErr << ")";
      EXPECT_LE(metalMax, 1.01f);
      EXPECT_EQ(ggxMetalOff, 0u) << "GGX white metal pixels off 1 by more than 0.01 (worst " << worstGgxMetal << ")";
      EXPECT_LE(dielectricMax, 1.9f);  // brdf.h's own albedo: 1.03 at n.v = 0.5, 1.55 at 0.1, 1.89 at 0 (roughness 0)
      std::printf(
          "furnace %s %s: brightest metal %.4f, dielectric %.4f; largest difference to the albedo %.4f;\n"
          "  the sphere centres (1 - value: the energy lost):\n",
          brdf == BRDF_GGX ? "ggx" : "beckmann", enumName(p.shading), metalMax, dielectricMax, worstErr);
      for (int row = 0; row < 2; ++row) {
        std::printf("  metal %d:", row);
        for (int col = 0; col < kCols; ++col) {
          const glm::ivec2 c = pixelOf(v, centreOf(row, col));
          std::printf(" r%.1f %.3f", roughnessOf(col), img.at(uint32_t(c.x), uint32_t(c.y)).g);
        }
        std::printf("\n");
      }
    }
}

// A sun 10^5 times the sky. Stated bounds: every pixel finite and at most 60000 (the shading passes' cap,
// under half float's maximum); on the rough spheres (roughness >= 0.6, cube levels 2-4) no pixel above what
// the lobe can gather: sky 1 + the sun's energy Phi (radiance x solid angle) x the lobe's peak density
// 1 / (pi alpha²) over its least upper-hemisphere mass (1/4, at alpha = 1), plus the diffuse, at most
// 1 + 1.1 Phi / pi (SH bands 0-2 overshoot a point by 6 %); alpha of the sharper cube level read. A sample
// that alone hits the sun, unfiltered, gives about 1e5 / (samples / 2): far above it. And no fireflies: no
// pixel of roughness >= 0.4 above 8 times the mean of its four neighbours + 1.
TEST_F(EnvironmentShadingTest, SunIsFiniteAndWithoutFireflies) {
  const Scene scene = sphereGrid(glm::vec3(1.0f));
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  render::HeadlessRenderer r(*ctx, gpu, kE);
  const ImageF map = sunMap();
  const auto maps = std::make_shared<const render::EnvironmentMaps>(*ctx, Environment(map, 1.0f, 0.0f));
  r.renderer().setEnvironment(maps);
  const double sunSolidAngle = 2 * M_PI / 512 * (std::cos(56.0 / 256 * M_PI) - std::cos(57.0 / 256 * M_PI));
  const double phi = (1e5 - 1.0) * sunSolidAngle;
  const uint32_t levels = maps->settings().specularLevels;
  const View v = gridView(scene);
  std::vector<Hit> hits;
  for (uint32_t y = 0; y < kE.height; ++y)
    for (uint32_t x = 0; x < kE.width; ++x) hits.push_back(hitOf(v, x, y));
  for (int brdf : {BRDF_GGX, BRDF_BECKMANN})
    for (const Path& p : paths()) {
      SCOPED_TRACE(testing::Message() << (brdf == BRDF_GGX ? "ggx, " : "beckmann, ") << enumName(p.shading));
      const ImageF img = r.render(v.pose, v.lens, envSettings(p, brdf), 1, true).sceneColor;
      float brightest = 0.0f, worstRatio = 0.0f;
      size_t fireflies = 0, aboveBound = 0;
      for (uint32_t y = 1; y + 1 < kE.height; ++y)
        for (uint32_t x = 1; x + 1 < kE.width; ++x) {
          const glm::vec4 px = img.at(x, y);
          ASSERT_TRUE(std::isfinite(px.r) && std::isfinite(px.g) && std::isfinite(px.b)) << x << "," << y;
          if (!covered(px)) continue;
          brightest = std::max(brightest, px.g);
          const Hit h = hits[size_t(y) * kE.width + x];
          if (h.sphere < 0) continue;
          const float rough = roughnessOf(h.sphere % kCols);
          if (rough >= 0.6f) {
            const float lo = std::floor(rough * float(levels - 1) + 1e-4f) / float(levels - 1);
            const double alpha = std::max(lo * lo, shader::BRDF_ALPHA_MIN);
            const double bound = 2.0 + phi * (1.0 / (M_PI * alpha * alpha) + 1.1 / M_PI);
            aboveBound += px.g > bound;
            worstRatio = std::max(worstRatio, float(px.g / bound));
          }
          const glm::vec4 nb[4] = {img.at(x - 1, y), img.at(x + 1, y), img.at(x, y - 1), img.at(x, y + 1)};
          bool inside = true;
          float mean = 0.0f;
          for (const glm::vec4& q : nb) inside &= covered(q), mean += 0.25f * q.g;
          if (inside && rough >= 0.4f && px.g > 8.0f * mean + 1.0f) ++fireflies;
        }
      EXPECT_LE(brightest, 60000.0f);
      EXPECT_EQ(aboveBound, 0u);
      EXPECT_EQ(fireflies, 0u);
      std::printf("sun %s %s: brightest pixel %.1f; rough spheres at most %.2f of their bound\n",
                  brdf == BRDF_GGX ? "ggx" : "beckmann", enumName(p.shading), brightest, worstRatio);
    }
}

// No environment is the renderer of before: setting one changes the image, taking it away gives the
// first image back byte for byte; the background colour changes only the pixels nothing covers.
TEST_F(EnvironmentShadingTest, NoEnvironmentIsTheImageOfBefore) {
  const Scene scene = sphereGrid(glm::vec3(0.8f, 0.5f, 0.3f));
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  render::HeadlessRenderer r(*ctx, gpu, kE);
  const View v = gridView(scene);
  for (const Path& p : paths()) {
    SCOPED_TRACE(enumName(p.shading));
    render::RenderSettings s;  // the library's defaults: headlight, ambient 0.02, black background
    s.shading = p.shading;
    s.raster = p.raster;
    const ImageRGBA8 before = r.render(v.pose, v.lens, s).image;
    r.renderer().setEnvironment(std::make_shared<const render::EnvironmentMaps>(*ctx, Environment(sunMap(), 1.0f, 0.0f)));
    EXPECT_NE(r.render(v.pose, v.lens, s).image.pixels, before.pixels);
    r.renderer().setEnvironment(nullptr);
    EXPECT_EQ(r.render(v.pose, v.lens, s).image.pixels, before.pixels);
    s.background = glm::vec3(0.18f);
    const ImageRGBA8 grey = r.render(v.pose, v.lens, s).image;
    size_t changed = 0, wrong = 0;
    for (size_t i = 0; i < grey.pixels.size(); i += 4) {
      const bool same = std::equal(&grey.pixels[i], &grey.pixels[i + 3], &before.pixels[i]);
      const bool wasEmpty = !(before.pixels[i] | before.pixels[i + 1] | before.pixels[i + 2]);
      changed += !same;
      wrong += !same && (!wasEmpty || std::abs(int(grey.pixels[i]) - 118) > 1);  // linear 0.18 is sRGB 118
    }
    EXPECT_GT(changed, grey.pixels.size() / 8);
    EXPECT_EQ(wrong, 0u);
  }
}

// A black dielectric model (base colour 0, no lights) is a silhouette against the grey backdrop; an
// environment lights it (its specular reflection: F0 = 0.04), and shows behind it.
TEST_F(EnvironmentShadingTest, EnvironmentLightsABlackModel) {
  const Scene scene = sphereGrid(glm::vec3(0.0f), false);
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  render::HeadlessRenderer r(*ctx, gpu, kE);
  const View v = gridView(scene);
  for (const Path& p : paths()) {
    SCOPED_TRACE(enumName(p.shading));
    render::RenderSettings s;
    s.shading = p.shading;
    s.raster = p.raster;
    s.lights = LightRig{{}, glm::vec3(0.0f), {}};
    s.background = glm::vec3(0.18f);
    s.backdropBlur = -1.0f;
    r.renderer().setEnvironment(nullptr);
    const ImageF dark = r.render(v.pose, v.lens, s, 1, true).sceneColor;
    r.renderer().setEnvironment(std::make_shared<const render::EnvironmentMaps>(*ctx, Environment(uniformMap(2.0f), 1.0f, 0.0f)));
    const ImageF lit = r.render(v.pose, v.lens, s, 1, true).sceneColor;
    s.backdropBlur = 0.0f;
    const ImageF behind = r.render(v.pose, v.lens, s, 1, true).sceneColor;
    size_t model = 0, litModel = 0;
    for (size_t i = 0; i < dark.pixels.size(); ++i) {
      if (std::abs(dark.pixels[i].g - 0.18f) < 1e-3f) {  // the backdrop: the colour, then the environment's radiance 2
        EXPECT_NEAR(lit.pixels[i].g, 0.18f, 1e-3f);
        EXPECT_NEAR(behind.pixels[i].g, 2.0f, 0.01f);
        continue;
      }
      ++model;
      EXPECT_EQ(dark.pixels[i].g, 0.0f);    // black on grey
      litModel += lit.pixels[i].g > 0.01f;  // F0 A + B of radiance 2: 0.03 at roughness 1, more elsewhere
    }
    EXPECT_GT(model, dark.pixels.size() / 20);
    EXPECT_EQ(litModel, model);
  }
}

// The environment's debug views (modes 14, 15) are the two terms the shaded view adds for it: they sum to
// the shaded image lit by the environment alone, the metals have no diffuse, both scale with the
// environment's intensity, and without an environment both are black (forward path: the debug views').
TEST_F(EnvironmentShadingTest, EnvironmentViewsAreTheShadedViewsTerms) {
  const Scene scene = sphereGrid(glm::vec3(0.8f, 0.5f, 0.3f));
  render::GpuScene gpu(*ctx, scene, render::MipMode::Compute);
  render::HeadlessRenderer r(*ctx, gpu, kE);
  const View v = gridView(scene);
  const Path forward = paths()[0];
  const auto render = [&](int mode) {
    render::RenderSettings s = envSettings(forward, BRDF_GGX);
    s.mode = mode;
    return r.render(v.pose, v.lens, s, 1, true).sceneColor;
  };
  size_t black = 0;
  for (int mode : {VIEW_ENV_DIFFUSE, VIEW_ENV_SPECULAR})
    for (const glm::vec4& px : render(mode).pixels) {
      if (!covered(px)) continue;
      ++black;
      ASSERT_EQ(glm::vec3(px), glm::vec3(0.0f)) << "mode " << mode << " without an environment";
    }
  EXPECT_GT(black, 2 * kE.width * kE.height / 20);
  std::vector<ImageF> diffuse, specular;
  for (float intensity : {1.0f, 2.0f}) {
    r.renderer().setEnvironment(std::make_shared<const render::EnvironmentMaps>(*ctx, Environment(sunMap(), intensity, 0.0f)));
    diffuse.push_back(render(VIEW_ENV_DIFFUSE));
    specular.push_back(render(VIEW_ENV_SPECULAR));
    const ImageF shaded = render(VIEW_SHADED);
    size_t n = 0, metal = 0;
    for (uint32_t y = 0; y < kE.height; ++y)
      for (uint32_t x = 0; x < kE.width; ++x) {
        const glm::vec4 s = shaded.at(x, y), d = diffuse.back().at(x, y), p = specular.back().at(x, y);
        if (!covered(s)) continue;
        ++n;
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(d[c] + p[c], s[c], 2e-3f * std::max(1.0f, s[c])) << x << "," << y;
        const Hit h = hitOf(v, x, y);
        if (h.sphere >= kCols && h.nv > 0.15f) {  // the metal row, off the silhouette
          ++metal;
          EXPECT_EQ(d.g, 0.0f) << x << "," << y;
          EXPECT_GT(p.g, 0.0f) << x << "," << y;
        }
      }
    EXPECT_GT(n, kE.width * kE.height / 20);
    EXPECT_GT(metal, n / 4);
  }
  size_t scaled = 0;
  for (size_t i = 0; i < diffuse[0].pixels.size(); ++i) {
    if (!covered(diffuse[0].pixels[i])) continue;
    EXPECT_NEAR(diffuse[1].pixels[i].g, 2.0f * diffuse[0].pixels[i].g, 2e-3f * std::max(1.0f, diffuse[1].pixels[i].g));
    EXPECT_NEAR(specular[1].pixels[i].g, 2.0f * specular[0].pixels[i].g, 2e-3f * std::max(1.0f, specular[1].pixels[i].g));
    scaled += diffuse[0].pixels[i].g > 0.01f;
  }
  EXPECT_GT(scaled, kE.width * kE.height / 40);  // the dielectrics' diffuse
}

}  // namespace
}  // namespace rtr
