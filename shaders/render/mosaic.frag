#version 460
// Mosaic post-process as a full-screen fragment pass (MosaicMode::Graphics); see mosaic.comp.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "mosaic.h"
#include "render/color8.glsl"

layout(set = 0, binding = 0) uniform texture2D sceneColor;  // linear light
layout(push_constant) uniform Push { MosaicPush pc; };
layout(location = 0) out vec4 outColor;  // UNORM attachment

void main() {
  const ivec2 p = ivec2(gl_FragCoord.xy);  // pixel centres are at .5: truncation gives the pixel
  const vec4 c = texelFetch(sceneColor, mosaicSource(p, pc.block, pc.size), 0);
  outColor = encode8(vec4(c.rgb, 1.0), true);
}
