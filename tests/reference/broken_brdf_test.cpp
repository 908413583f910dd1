// The reference comparison has teeth: the GPU side is rendered with shaders compiled at run time
// against an edited copy of shaders/shared/brdf.h (shaderFolderWith: the sources are untouched; the CPU
// tracer keeps the real BRDF), and the comparison must fail. A control compiles the unedited copy the same way
// and must pass, so a failure is the edit's doing, not the run-time compile path's.
#include <gtest/gtest.h>

#include "test_paths.hpp"

#include "reference_common.hpp"
#include "vk_fixture.hpp"

namespace rtr::reftest {
namespace {

// Fresnel dropped: Schlick's angle-dependent term removed, F = F0 at every angle.
const ShaderEdit kNoFresnel{"fresnel_dropped", "shared/brdf.h", "return F0 + (vec3(1.0f) - F0) * (x2 * x2 * x);", "return F0;"};
// Beckmann alpha = roughness instead of roughness^2 (a classic remapping slip).
const ShaderEdit kAlphaLinear{"alpha_not_squared", "shared/brdf.h", "return max(r * r, BRDF_ALPHA_MIN);",
                              "return max(r, BRDF_ALPHA_MIN);"};

class BrokenBrdfTest : public test::VulkanTest {
 protected:
  CompareResult run(const ShaderEdit& edit, const std::string& caseName) {
    const auto poses = loadPoses(posesFile());
    const ReferenceScene rs = makeScene(caseName, outDir() / "work");
    const CasePair pair = renderPair(*ctx, rs, poses.at(caseName), View::Shaded, {.shaderDir = shaderFolderWith(edit)});
    EXPECT_EQ(blankReason(pair.gpu), "") << caseName + " GPU";
    const Limits lim = limits(View::Shaded);
    const CompareResult r = compareEdgeTolerant(pair.gpu, pair.cpu, lim.threshold);
    writeOutputs(std::string("broken_") + edit.name + "_" + caseName, pair, r, lim);
    return r;
  }
};

TEST_F(BrokenBrdfTest, ControlCompiledAtRunTimePasses) {
  for (const char* c : {"grazing_floor", "metal_sphere"})
    EXPECT_LE(run(kNoEdit, c).failingFraction, limits(View::Shaded).maxFailingFraction) << c;
}

TEST_F(BrokenBrdfTest, DroppedFresnelFailsAtGrazingAngles) {
  EXPECT_GT(run(kNoFresnel, "grazing_floor").failingFraction, limits(View::Shaded).maxFailingFraction);
}

TEST_F(BrokenBrdfTest, UnsquaredRoughnessFailsOnTheMetalSphere) {
  EXPECT_GT(run(kAlphaLinear, "metal_sphere").failingFraction, limits(View::Shaded).maxFailingFraction);
}

}  // namespace
}  // namespace rtr::reftest
