// The text overlay's rectangles (src/render/text_overlay.cpp fills them from stb_easy_font's quads; text.vert
// draws two triangles per rectangle). Shared by GLSL and C++.
#ifndef RTR_SHADERS_SHARED_TEXT_H
#define RTR_SHADERS_SHARED_TEXT_H

#include "shared.h"
#ifdef __cplusplus
namespace rtr::shader {
using glm::vec2;
using glm::vec4;
#endif

struct TextRect {
  vec4 rect;   // x0, y0, x1, y1 in pixels, y down
  vec4 color;  // written as is: the target holds sRGB-encoded bytes already
};

struct TextPush {
  vec2 pixelToNdc;  // 2 / target size
};

#ifdef __cplusplus
}  // namespace rtr::shader
#endif

#endif
