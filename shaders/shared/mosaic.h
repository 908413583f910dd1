// The mosaic rule (brief part 2, section 1.7) and its push constants, shared by GLSL (mosaic.comp and
// mosaic.frag, so the compute and graphics paths are bit-identical) and C++ (src/render/post.cpp).
#ifndef RTR_SHADERS_SHARED_MOSAIC_H
#define RTR_SHADERS_SHARED_MOSAIC_H

#include "shared.h"
#ifdef __cplusplus
namespace rtr::shader {
using glm::ivec2;
using glm::min;
#endif

// mosaic.comp workgroup: one thread per block, MOSAIC_GROUP_X blocks wide, MOSAIC_GROUP_Y block rows
#define MOSAIC_GROUP_X 64
#define MOSAIC_GROUP_Y 4

struct MosaicPush {
  ivec2 block;  // block size in pixels; 5x3 by default, 1x1 is a plain copy (MosaicMode::Off)
  ivec2 size;   // image size in pixels
};

// The pixel whose value fills every pixel of the block containing p: the block's centre pixel
// (block / 2 from its top-left corner), clamped into the image for the partial blocks at the right and
// bottom edges, so the chosen pixel always lies inside its own block.
RTR_FN ivec2 mosaicSource(ivec2 p, ivec2 block, ivec2 size) {
  return min((p / block) * block + block / 2, size - ivec2(1));
}

#ifdef __cplusplus
}  // namespace rtr::shader
#endif

#endif
