#pragma once
// Rendering one reference case on both sides, the limits, and the files a person looks at.
#include <filesystem>
#include <optional>
#include <string>

#include "core/compare.hpp"
#include "core/image.hpp"
#include "reference_scenes.hpp"
#include "render/renderer.hpp"
#include "scene/load.hpp"
#include "vk/context.hpp"

namespace rtr::reftest {

constexpr uint32_t kW = 160, kH = 120;

// GPU view mode <-> tracer shading.
//   Shaded:  GPU mode 1 (VIEW_SHADED)       vs Tracer Shading::Pbr, shadows off, 0 bounces.
//   Normals: GPU mode 5 (VIEW_NORMAL, |n|)  vs Shading::Normals (|n|): same definition, no mapping.
//   Depth:   GPU mode 3 (view depth / far)  vs Shading::Depth (t·dot(d, forward) / far): same definition and
//            the same far (the GPU gets the tracer's fitted lens); misses are 1 (white) on the CPU and the
//            clear colour 0 on the GPU, so CPU misses are mapped to 0 (see docs/reference-tests.md).
enum class View { Shaded, Normals, Depth };
const char* viewName(View v);

struct Limits {
  int threshold;              // per channel, 8-bit sRGB steps, against the best of the 3x3 reference pixels
  double maxFailingFraction;  // of all pixels
};
Limits limits(View v);
// A case's limits: limits(v), except the textured temple's shaded view, which is looser because the GPU's
// derivative LOD and the tracer's ray-cone LOD differ by a fraction of a level (docs/reference-tests.md).
Limits limits(const std::string& caseName, View v);

struct CasePair {
  ImageRGBA8 gpu;           // toSrgb8(the GPU's linear intermediate image)
  ImageRGBA8 gpuDisplayed;  // the GPU's post-pass output (mosaic off), as the viewer shows it
  ImageRGBA8 cpu;           // toSrgb8(the tracer's linear image)
  // Filled when PairOptions::benchFrames > 0: GPU frame time (median of the frames' summed passes) and the
  // tracer's wall time for the same image.
  double gpuMs = 0, cpuMs = 0;
  uint64_t cpuRays = 0;
  // Linear images (the scene colour and the tracer's radiance); environment cases mark the pixels no
  // surface covers with kUncovered on both sides.
  ImageF gpuLinear, cpuLinear;
  std::vector<std::pair<std::string, double>> prefilterMs;  // the environment's GPU passes (environment cases)
};

// Environment cases: what the pixels that no surface covers hold on both sides (no shading writes a
// negative value), so that only surfaces are compared.
constexpr float kUncovered = -1.0f;

struct PairOptions {
  uint32_t width = kW, height = kH;
  unsigned threads = 2;  // tracer threads (and BVH build threads)
  int benchFrames = 0;   // > 0: time that many GPU frames after a warm-up, and time the trace
  // Compiled shaders to use for the GPU instead of the build's (RTR_SHADER_DIR for the lifetime of the
  // renderer's pipeline creation); used by the broken-BRDF test.
  std::optional<std::filesystem::path> shaderDir;
  render::RasterPath raster = render::RasterPath::Auto;  // who rasterises the shaded view's visibility ids
  int spp = 256;                                         // the tracer's sample pairs a pixel in environment cases
};

// Renders a case on both sides.
CasePair renderPair(const vk::Context& ctx, const ReferenceScene& rs, const PoseEntry& pose, View view,
                    const PairOptions& options = {});

// The GPU's split sum against the tracer over the pixels both cover (environment cases), linear RGB.
struct EnvError {
  size_t pixels = 0;
  double meanAbs = 0, maxAbs = 0;  // |gpu - cpu| per channel, radiance units
  double meanRef = 0;              // the reference's mean value: meanAbs / meanRef is the error relative to it
  // The mean over pixels of |gpu - cpu| / cpu (channel sums; cpu at least 5 % of the mean pixel, so black
  // pixels do not divide by zero): the error "as a share of the pixel value".
  double meanPixelRelative = 0;
  double relative() const { return meanRef > 0 ? meanAbs / meanRef : 0.0; }
};
// Over the pixels both images cover; `mask` (optional, one entry a pixel) limits it to where it is true.
EnvError envError(const ImageF& test, const ImageF& ref, const std::vector<bool>* mask = nullptr);
// The part (ReferenceScene::parts) each pixel belongs to: the nearest projected centre; -1 uncovered.
std::vector<int> partOfPixels(const ReferenceScene& rs, const PoseEntry& pose, uint32_t width, uint32_t height,
                              const ImageF& coverage);

// The tracer's side of renderPair alone (its linear image), e.g. at other sample counts.
ImageF traceCase(const ReferenceScene& rs, const PoseEntry& pose, View view, const PairOptions& options = {},
                 trace::RenderStats* stats = nullptr);

// The tracer's settings for a case (the pose, lens, shading and light both sides use).
trace::TraceSettings traceSettings(const ReferenceScene& rs, const PoseEntry& pose, View view, const PairOptions& options);

// Environment cases without textures: the split sum evaluated exactly on the CPU (env_split.cpp): every
// texel of the map summed for the prefiltered radiance, the table's integrals by 4096 samples, the SH of
// the whole map. Against the tracer: the approximation's own error; against the GPU: the implementation's.
// Pixels of materials rougher than `maxRoughness` are left uncovered (the mirrors alone are cheap).
ImageF splitSumCase(const ReferenceScene& rs, const PoseEntry& pose, const PairOptions& options, float maxRoughness = 1.0f);

// A shader source edit for the tests that break the GPU side on purpose: in `file` (relative to shaders/),
// the exact text `from` becomes `to`; an empty `from` is no edit (the control).
struct ShaderEdit {
  std::string name, file, from, to;
};
inline const ShaderEdit kNoEdit{"control", "", "", ""};
// A shader folder (for PairOptions::shaderDir): every compiled shader of the build, with the shaded view's
// shaders (pbr.frag, vis_shade.comp, every variant) recompiled from a copy of shaders/ with `edit` applied.
// Throws rtr::Error when the text to edit is not found (the test would prove nothing).
std::filesystem::path shaderFolderWith(const ShaderEdit& edit);

std::filesystem::path posesFile();
std::filesystem::path outDir();  // <build>/reference-out, created

// Why an image is blank, or "" when it is not: under 5% of pixels above 2/255 in some channel, or one
// colour only (a flat plane's normal view legitimately has just two: background and the plane). A
// comparison of two black images proves nothing.
std::string blankReason(const ImageRGBA8& img);

// <id>_gpu.png, <id>_cpu.png, <id>_err.png and <id>.txt (one line: the numbers) in outDir(); the line is
// also printed.
void writeOutputs(const std::string& id, const CasePair& pair, const CompareResult& r, const Limits& lim);

}  // namespace rtr::reftest
