#pragma once
// The compute rasteriser of the visibility buffer (docs/raster.md): a clear pass, one workgroup per
// cluster writing (depth << 32 | id) per pixel with 64-bit atomicMin, a pass clipping the triangles that
// cross w = 0 or leave the guard band, a pass over the large triangles' tiles, and an indirect hardware draw
// of what it hands off (those triangles where clipping is off, and what the lists cannot hold) into the
// same buffer. A scene with alpha-masked materials gets the passes' variant that tests
// the mask per pixel (docs/raster.md); others bind no texture.
// RASTER_SHARED_AREA (raster.h, a specialization constant of both passes): the bounding-box area in pixels
// above which a triangle is rasterised by tiles rather than by its own thread.
#include <array>
#include <optional>
#include <vector>

#include "render/cull.hpp"
#include "render/gpu_scene.hpp"
#include "vk/commands.hpp"
#include "vk/frame_ring.hpp"
#include "vk/pipeline.hpp"

namespace rtr::render {

class ComputeRaster {
 public:
  // Whether the device has what it needs (64-bit buffer atomics, also in fragment shaders).
  static bool supported(const vk::Context& ctx);
  // Its pipelines, made from the scene's kinds alone (in parallel; Renderer::prepare, before the upload).
  struct Pipelines {
    vk::Pipeline clear, raster, clip, large, hardware;
  };
  static Pipelines makePipelines(const vk::Context& ctx, const SceneKinds& kinds);
  // `made`: its pipelines made ahead for this scene's kinds; none: made here.
  ComputeRaster(const vk::Context& ctx, const GpuScene& scene, uint32_t framesInFlight, std::optional<Pipelines> made = {});

  void resize(VkExtent2D extent);  // the caller has waited for the device to be idle
  // Records the passes, each timed ("clear", "raster", "raster clip", "raster large", "raster hw"); afterwards ids() is
  // written (compute and fragment stages), for a compute reader after a barrier the caller makes (vis_shade).
  // With `cull` (the frame's camera), two-phase cluster culling (docs/culling.md): "cull early" lists the
  // clusters visible last frame, "raster early" + "raster large early" draw them, "pyramid" reduces their
  // depth, "cull" tests the rest against it, and the passes above draw those; the hardware hand-off once.
  // Level of detail (docs/virtual-geometry.md): with a scene hierarchy and camera.lodThreshold > 0, the
  // culling pass picks each instance's clusters of the cut (without `cull`: one pass, "cull", testing
  // nothing else); otherwise only the full-detail clusters are drawn.
  // `clip`: the triangles crossing w = 0 or the guard band are clipped in compute ("raster clip", once per
  // raster pass); otherwise the hardware draws them ("raster hw", the reference).
  void record(VkCommandBuffer cb, const vk::UploadArena::Slice& uniforms, vk::GpuTimer& timer, uint32_t frame,
              const CullCamera& camera, Culling cull, bool clip, bool counters = true);
  // Whether the last use of `frame` read its counters back (record's `counters`).
  bool counted(uint32_t frame) const { return counted_.at(frame); }
  VkBuffer ids() const { return vis_.handle(); }  // uint64 per pixel, row by row
  // The clear folded into shading (docs/raster.md, "The clear left to shading"). The rule: record() clears
  // every pixel unless the buffer is known clear (RASTER_CLEAR in every word), which it is only after a
  // frame whose ids' one reader, the shading pass, wrote RASTER_CLEAR back into every word it read (the
  // caller says so with shadingCleared()); then "clear" only resets the lists (one workgroup). Not known
  // clear: the first frame, after resize() (a new buffer), after a frame that kept its ids for a later
  // reader (the transparency pass, a read-back), and in a rasteriser made again (a pipeline reload).
  // foldClear(): whether the shading may clear them (RTR_CLEAR_IN_SHADE, read when made; 0: never, so the
  // full clear every frame).
  bool foldClear() const { return foldClear_; }
  // The caller recorded, after this frame's record(), a shading pass that cleared every word it read.
  void shadingCleared() { visClear_ = true; }
  // Whether ids() holds no ids now (the last frame's were cleared by its shading pass).
  bool idsCleared() const { return visClear_; }
  // The passes' texture arrays (set 1 of the layouts that have one), for the one writer of every texture set.
  std::vector<std::pair<const vk::PipelineLayout*, VkDescriptorSet>> textureSets() const;
  // The culling counts of the last completed use of `frame` (none if it did not cull).
  struct CullStats {
    uint32_t clusters = 0, early = 0, late = 0;              // listed by each phase (one pass: late)
    uint32_t frustum = 0, cone = 0, occlusion = 0, lod = 0;  // culled, by the late phase (every cluster tested)
    uint32_t triangles = 0;                                  // of the listed clusters, both phases
    uint32_t tested = 0;                                     // clusters visited, both phases (those of the instances not culled)
    uint32_t instancesCulled = 0;                            // by the late phase's frustum test, whole
    uint32_t nodes = 0;                                      // tree nodes tested, both phases
  };
  std::optional<CullStats> cullStats(uint32_t frame) const;
  // Triangles handed to the hardware by the last completed use of `frame` (both phases); those past
  // handOffCapacity() were not drawn.
  uint32_t handOffTriangles(uint32_t frame) const;
  // Triangles clipped in compute by the last completed use of `frame` (both phases; 0 with clipping off).
  uint32_t clippedTriangles(uint32_t frame) const;
  // Medium triangles found by the last completed use of `frame` (both phases; raster.h): those of 16 lanes
  // and of 32 (`narrow`, `wide`), and of those `pastList`, drawn by their own thread.
  struct MediumCounts {
    uint32_t narrow = 0, wide = 0, pastList = 0;
    uint32_t total() const { return narrow + wide; }
  };
  MediumCounts mediumTriangles(uint32_t frame) const;
  uint32_t mediumCapacity() const { return mediumCapacity_; }  // records (raster.h)
  uint32_t handOffCapacity() const { return handOffCapacity_; }

 private:
  const vk::Context& ctx_;
  const GpuScene& scene_;
  vk::Pipeline clear_, raster_, clip_, large_, hardware_;
  vk::DescriptorSets textures_[4];  // set 1 of textured()'s pipelines where they have one
  std::array<const vk::Pipeline*, 4> textured() const { return {&raster_, &clip_, &large_, &hardware_}; }
  vk::Buffer vis_, hwList_, clipList_, largeList_, largeTris_;
  uint32_t handOffCapacity_ = 1, mediumCapacity_ = 1;
  // Per frame in flight in handOffReadback_: the hand-off's vertex count, the clipped triangles, LargeList's
  // mediumFound and mediumStored.
  static constexpr VkDeviceSize kReadbackSize = 24;
  VkExtent2D extent_{0, 0};
  bool foldClear_ = true;                // RTR_CLEAR_IN_SHADE
  bool visClear_ = false;                // vis_ holds RASTER_CLEAR in every word once the frames recorded so far have run
  std::optional<ClusterCuller> culler_;  // made on the first culled frame; the pyramid per size
  std::optional<DepthPyramid> pyramid_;
  vk::Buffer cullReadback_;     // per frame in flight: the early and the late CullCounts
  vk::Buffer handOffReadback_;  // per frame in flight: kReadbackSize bytes
  std::vector<bool> culled_;    // per frame in flight: whether its last use culled
  std::vector<bool> twoPhase_;  // per frame in flight: whether that was in two phases
  std::vector<bool> counted_;   // per frame in flight: whether its counters were read back
};

}  // namespace rtr::render
