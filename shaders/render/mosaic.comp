#version 460
// Mosaic post-process in compute (MosaicMode::Compute; block 1x1 for MosaicMode::Off): one thread per
// output pixel, same rule and encode as mosaic.frag, so both paths give the same bytes.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "mosaic.h"
#include "render/color8.glsl"

layout(local_size_x = MOSAIC_GROUP, local_size_y = MOSAIC_GROUP) in;

layout(set = 0, binding = 0) uniform texture2D sceneColor;  // linear light
layout(set = 0, binding = 1) writeonly uniform image2D outputImage;  // UNORM; no format: BGRA works too
layout(push_constant) uniform Push { MosaicPush pc; };

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, pc.size))) return;
  const vec4 c = texelFetch(sceneColor, mosaicSource(p, pc.block, pc.size), 0);
  imageStore(outputImage, p, encode8(vec4(c.rgb, 1.0), true));
}
