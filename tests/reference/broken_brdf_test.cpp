// The reference comparison has teeth: the GPU side is rendered with shaders compiled at run time
// against an edited copy of shaders/shared/brdf.h (the shared header itself is untouched; the CPU tracer
// keeps the real BRDF), and the comparison must fail. A control compiles the unedited copy the same way
// and must pass, so a failure is the edit's doing, not the run-time compile path's.
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "test_paths.hpp"

#include "core/error.hpp"
#include "reference_common.hpp"
#include "vk/glsl.hpp"
#include "vk/pipeline.hpp"
#include "vk_fixture.hpp"

namespace rtr::reftest {
namespace {

struct Edit {
  const char* name;
  const char* from;  // exact text in brdf.h; empty: no edit (control)
  const char* to;
};

constexpr Edit kControl{"control", "", ""};
// Fresnel dropped: Schlick's angle-dependent term removed, F = F0 at every angle.
constexpr Edit kNoFresnel{"fresnel_dropped", "return F0 + (vec3(1.0f) - F0) * (x2 * x2 * x);", "return F0;"};
// Beckmann alpha = roughness instead of roughness^2 (a classic remapping slip).
constexpr Edit kAlphaLinear{"alpha_not_squared", "return max(r * r, BRDF_ALPHA_MIN);", "return max(r, BRDF_ALPHA_MIN);"};

std::string readAll(const std::filesystem::path& f) {
  std::ifstream in(f, std::ios::binary);
  if (!in) throw Error(f.string() + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A shader folder: every compiled shader of the build, with the shaded view's shaders (forward and
// visibility path) recompiled against brdf.h with `edit` applied.
std::filesystem::path shaderFolderWith(const Edit& edit) {
  const std::filesystem::path src = test::sourceDir() / "shaders";
  const std::filesystem::path dir = outDir() / "work" / (std::string("shaders_") + edit.name);
  const std::filesystem::path inc = dir / "include";
  std::filesystem::create_directories(inc);
  for (const auto& e : std::filesystem::directory_iterator(vk::shaderDir()))
    if (e.path().extension() == ".spv")
      std::filesystem::copy_file(e.path(), dir / e.path().filename(), std::filesystem::copy_options::overwrite_existing);
  std::string brdf = readAll(src / "shared/brdf.h");
  if (*edit.from) {
    const size_t at = brdf.find(edit.from);
    if (at == std::string::npos) throw Error(std::string("brdf.h no longer contains '") + edit.from + "'");
    brdf.replace(at, std::string(edit.from).size(), edit.to);
  }
  std::ofstream(inc / "brdf.h", std::ios::binary) << brdf;
  // The shaded view's shaders of both paths (forward fragment, visibility compute, from either rasteriser's
  // ids) include "brdf.h":
  // not found next to them (shaders/), so the edited copy comes first.
  for (const char* shader : {"pbr.frag", "vis_shade.comp"}) {  // every variant of each (variants.h)
    const vk::SpirvModule m = vk::compileGlsl(src / shader, {inc, src, src / "shared"});
    std::ofstream out(dir / (std::string(shader) + ".spv"), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(m.code.data()), std::streamsize(m.code.size() * sizeof(uint32_t)));
    if (!out) throw Error("cannot write " + (dir / shader).string() + ".spv");
  }
  return dir;
}

class BrokenBrdfTest : public test::VulkanTest {
 protected:
  CompareResult run(const Edit& edit, const std::string& caseName) {
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
    EXPECT_LE(run(kControl, c).failingFraction, limits(View::Shaded).maxFailingFraction) << c;
}

TEST_F(BrokenBrdfTest, DroppedFresnelFailsAtGrazingAngles) {
  EXPECT_GT(run(kNoFresnel, "grazing_floor").failingFraction, limits(View::Shaded).maxFailingFraction);
}

TEST_F(BrokenBrdfTest, UnsquaredRoughnessFailsOnTheMetalSphere) {
  EXPECT_GT(run(kAlphaLinear, "metal_sphere").failingFraction, limits(View::Shaded).maxFailingFraction);
}

}  // namespace
}  // namespace rtr::reftest
