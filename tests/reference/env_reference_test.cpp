// The GPU's split sum against the tracer's Monte Carlo (docs/environment.md, "How wrong the split sum
// is"): the sphere grid (metallic x roughness, GGX) under the sky without its sun (smooth light: the split
// sum's own error is small there; with the sun it is tens of percent and would hide a broken shader) at a
// small size stays within a bound measured on lavapipe, and the same comparison fails when the shading
// reads the prefiltered cube at the wrong mip or the other BRDF's rows of the split-sum table (edited
// shaders compiled at run time; the control compiles the unedited sources the same way).
#include <cstdio>
#include <memory>

#include <gtest/gtest.h>

#include "reference_common.hpp"
#include "vk_fixture.hpp"

namespace rtr::reftest {
namespace {

constexpr const char* kCase = "env_sphere_grid_nosun";
// 64 sample pairs, and the comparison is of 3x3 means of both images (the tracer's noise down by ~3).
constexpr int kSpp = 64;
// The bound on the mean per-pixel error. Measured at these settings (lavapipe, 160x120): 3.8 %; with every
// roughness read from the cube's sharpest level 7.0 %, with GGX reading Beckmann's table 13.2 %.
constexpr double kBound = 0.055;

// 3x3 box mean over the pixels both images cover (noise down by ~3, the split sum's smooth errors kept).
ImageF boxMean(const ImageF& img, const ImageF& other) {
  ImageF out = img;
  for (uint32_t y = 0; y < img.height; ++y)
    for (uint32_t x = 0; x < img.width; ++x) {
      if (img.at(x, y).r == kUncovered || other.at(x, y).r == kUncovered) continue;
      glm::vec4 sum(0.0f);
      int n = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = int(x) + dx, yy = int(y) + dy;
          if (xx < 0 || yy < 0 || xx >= int(img.width) || yy >= int(img.height)) continue;
          const glm::vec4 p = img.at(uint32_t(xx), uint32_t(yy)), q = other.at(uint32_t(xx), uint32_t(yy));
          if (p.r == kUncovered || q.r == kUncovered) continue;
          sum += p, ++n;
        }
      out.at(x, y) = sum / float(n);
    }
  return out;
}

class EnvReferenceTest : public test::VulkanTest {
 protected:
  EnvError run(const ShaderEdit& edit) {
    const auto poses = loadPoses(posesFile());
    const ReferenceScene rs = makeScene(kCase, outDir() / "work");
    PairOptions o;
    o.spp = kSpp;
    if (!edit.from.empty() || edit.name == kNoEdit.name) o.shaderDir = shaderFolderWith(edit);
    const CasePair pair = renderPair(*ctx, rs, poses.at(kCase), View::Shaded, o);
    EXPECT_EQ(blankReason(pair.gpu), "") << "GPU";
    EXPECT_EQ(blankReason(pair.cpu), "") << "CPU";
    const EnvError e = envError(boxMean(pair.gpuLinear, pair.cpuLinear), boxMean(pair.cpuLinear, pair.gpuLinear));
    const std::string id = std::string(kCase) + "_" + edit.name;
    const CompareResult r = compareEdgeTolerant(pair.gpu, pair.cpu, 3);
    writeOutputs(id, pair, r, limits(View::Shaded));
    std::printf("%s: %zu pixels, mean per-pixel error %.2f %% (bound %.1f %%), mean abs %.4f of mean pixel %.3f\n", id.c_str(),
                e.pixels, 100.0 * e.meanPixelRelative, 100.0 * kBound, e.meanAbs, e.meanRef);
    EXPECT_GT(e.pixels, 1000u);
    return e;
  }
};

// Measured on lavapipe (160x120): see docs/environment.md.
constexpr double kImplementationBound = 0.03;
// The mirror spheres (roughness 0), sphere by sphere: the report's goal. Measured on lavapipe (640x360,
// the sunlit grid): 0.1-1.3 % (the dielectric's diffuse, from SH of a 32²-a-face level, is the most);
// 10.9 % on the metallic-0.5 sphere that the sun's reflection lands on when the mirror read the cube's level 0.
constexpr double kMirrorBound = 0.02;

struct SplitSumError {
  double worst = 0;  // the worst sphere's error, % of its mean pixel
  size_t spheres = 0;
};

// What of a case implementationError compares: the image size, the spheres (those rougher than
// maxRoughness are left out) and the environment's rotation about +y.
struct SplitSumCheck {
  uint32_t width = kW, height = kH;
  float maxRoughness = 1.0f;
  float rotation = 0.0f;  // radians
};

// The GPU against the split sum evaluated exactly on the CPU (env_split.cpp): no tracer noise, so the bound
// is tight and holds with the sun too; what is left is the implementation's error (cube resolution,
// sampled levels, half floats, the table's texels).
SplitSumError implementationError(const vk::Context& ctx, const char* name, const ShaderEdit& edit, double bound,
                                  const SplitSumCheck& check = {}) {
  const auto poses = loadPoses(posesFile());
  ReferenceScene rs = makeScene(name, outDir() / "work");
  if (check.rotation != 0.0f) rs.environment = std::make_shared<const Environment>(rs.environment->map(), 1.0f, check.rotation);
  PairOptions o;
  o.width = check.width, o.height = check.height;
  o.spp = 1;  // the tracer's image only marks what is covered here
  if (!edit.from.empty()) o.shaderDir = shaderFolderWith(edit);
  const CasePair pair = renderPair(ctx, rs, poses.at(name), View::Shaded, o);
  const ImageF exact = splitSumCase(rs, poses.at(name), o, check.maxRoughness);
  const std::vector<int> part = partOfPixels(rs, poses.at(name), o.width, o.height, pair.cpuLinear);
  SplitSumError r;
  for (size_t k = 0; k < rs.parts.size(); ++k) {
    std::vector<bool> mask(part.size());
    for (size_t i = 0; i < part.size(); ++i) mask[i] = part[i] == int(k);
    const EnvError e = envError(pair.gpuLinear, exact, &mask);
    if (e.pixels == 0 && check.maxRoughness < 1.0f) continue;  // a sphere left out
    EXPECT_GT(e.pixels, 50u) << rs.parts[k].name;
    if (e.relative() > bound)
      std::printf("  %s: %.2f %% off the exact split sum\n", rs.parts[k].name.c_str(), 100.0 * e.relative());
    r.worst = std::max(r.worst, e.relative());
    ++r.spheres;
  }
  std::printf("%s %ux%u rotation %.2f %s: worst of %zu spheres %.2f %% off the exact split sum\n", name, o.width, o.height,
              check.rotation, edit.name.c_str(), r.spheres, 100.0 * r.worst);
  return r;
}

// The sunlit grid's five mirror spheres: at 640x360 the sun's one-texel reflection lands on a pixel of the
// metallic-0.5 one (at 160x120 and 320x180 on none); turned by `rotation`, at 160x120 (the mirror reads the
// map, which is stored unturned, so the rotation is applied where it is read).
SplitSumError mirrorError(const vk::Context& ctx, const ShaderEdit& edit, float rotation = 0.0f) {
  const SplitSumCheck check{
      .width = rotation == 0.0f ? 640u : kW, .height = rotation == 0.0f ? 360u : kH, .maxRoughness = 0.0f, .rotation = rotation};
  const SplitSumError e = implementationError(ctx, "env_sphere_grid", edit, kMirrorBound, check);
  EXPECT_EQ(e.spheres, 5u);
  return e;
}
constexpr float kRotation = 2.0f;

TEST_F(EnvReferenceTest, GpuMatchesTheExactSplitSum) {
  const ShaderEdit build{"build", "", "", ""};
  EXPECT_LE(implementationError(*ctx, "env_sphere_grid_nosun", build, kImplementationBound).worst, kImplementationBound);
  // With the sun: the sampled roughness-0.25 level's blotches were 3.3-9.8 % off here; it is summed since.
  EXPECT_LE(implementationError(*ctx, "env_sphere_grid", build, kImplementationBound).worst, kImplementationBound);
  EXPECT_LE(mirrorError(*ctx, build).worst, kMirrorBound);
  EXPECT_LE(mirrorError(*ctx, build, kRotation).worst, kMirrorBound);
}

TEST_F(EnvReferenceTest, GpuOffTheExactSplitSumWhenBroken) {
  EXPECT_GT(implementationError(*ctx, "env_sphere_grid_nosun",
                                {"env_mip_zero", "env_light.glsl", "rough * frame.environment.x", "0.0"}, kImplementationBound)
                .worst,
            kImplementationBound);
  EXPECT_GT(
      implementationError(*ctx, "env_sphere_grid_nosun",
                          {"env_lut_swapped", "env_light.glsl", "envLutUv(brdf,", "envLutUv(1 - brdf,"}, kImplementationBound)
          .worst,
      kImplementationBound);
  // The mirror read from the specular cube's level 0, as before it read the map; the map read unturned.
  EXPECT_GT(mirrorError(*ctx, {"env_mirror_from_cube", "env_light.glsl", "if (lod < 1.0)", "if (false)"}).worst, kMirrorBound);
  EXPECT_GT(
      mirrorError(*ctx, {"env_mirror_unturned", "env_light.glsl", "envDirToUv(r, frame.environment.w)", "envDirToUv(r, 0.0)"},
                  kRotation)
          .worst,
      kMirrorBound);
}

TEST_F(EnvReferenceTest, SphereGridSplitSumWithinBound) { EXPECT_LE(run({"build", "", "", ""}).meanPixelRelative, kBound); }

TEST_F(EnvReferenceTest, ControlCompiledAtRunTimePasses) { EXPECT_LE(run(kNoEdit).meanPixelRelative, kBound); }

// Every roughness read from the cube's sharpest level: rough spheres mirror the sky.
TEST_F(EnvReferenceTest, PrefilterMipIgnoredFails) {
  EXPECT_GT(run({"env_mip_zero", "env_light.glsl", "rough * frame.environment.x", "0.0"}).meanPixelRelative, kBound);
}

// GGX materials read Beckmann's rows of the table (a swapped table).
TEST_F(EnvReferenceTest, SwappedBrdfTableFails) {
  EXPECT_GT(run({"env_lut_swapped", "env_light.glsl", "envLutUv(brdf,", "envLutUv(1 - brdf,"}).meanPixelRelative, kBound);
}

}  // namespace
}  // namespace rtr::reftest
