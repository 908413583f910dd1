#pragma once
// Image-state tracking, kept small (no render graph): every image carries its layout and what last touched
// it; a pass says what it needs (`require`) and gets the one sync2 barrier that takes the image there from
// its last use, or none when nothing is needed (a read after reads in the same layout that already waited).
#include <initializer_list>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

namespace rtr::vk {

// How a pass uses an image; picks the layout and the access mask.
enum class Use {
  ColorAttachment,  // write (and read, when not discarding: blending or LOAD_OP_LOAD)
  DepthAttachment,  // depth test and write
  Sampled,          // read in shaders
  Storage,          // written in shaders (GENERAL)
  CopySrc,
  CopyDst,
  Present,  // ordered by the submit's semaphore: layout only
};

struct ImageState {
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
  // The last write (or layout change), and the stages that read since then, having already waited for it.
  VkPipelineStageFlags2 writeStage = VK_PIPELINE_STAGE_2_NONE;
  VkAccessFlags2 writeAccess = VK_ACCESS_2_NONE;
  VkPipelineStageFlags2 readStages = VK_PIPELINE_STAGE_2_NONE;
};

// An image and its state, wherever the state lives (a vk::Image's own, or a swapchain image's per frame).
struct TrackedImage {
  VkImage image = VK_NULL_HANDLE;
  ImageState* state = nullptr;
  const char* name = "image";  // in the printed barriers
  VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT;
};

struct Requirement {
  TrackedImage image;
  Use use;
  VkPipelineStageFlags2 stage;  // the stages that will access the image
  bool discard = false;         // previous contents not needed: the barrier starts from UNDEFINED
};

// Records one vkCmdPipelineBarrier2 holding the barriers these requirements need (nothing when none does)
// and updates the images' states. Covers mip level 0 and layer 0 with all mips (whole images).
void require(VkCommandBuffer cb, std::initializer_list<Requirement> reqs);
inline void require(VkCommandBuffer cb, TrackedImage image, Use use, VkPipelineStageFlags2 stage, bool discard = false) {
  require(cb, {Requirement{image, use, stage, discard}});
}

// The barriers recorded by require() between beginBarrierLog() and endBarrierLog(), one line per image
// barrier ("name: OLD -> NEW, SRC_STAGES/SRC_ACCESS -> DST_STAGES/DST_ACCESS"). FrameRing logs its second
// frame this way and prints it when RTR_PRINT_BARRIERS=1.
void beginBarrierLog();
std::vector<std::string> endBarrierLog();
bool barrierLogRequested();  // RTR_PRINT_BARRIERS=1

}  // namespace rtr::vk
