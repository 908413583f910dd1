#version 460
// Mosaic post-process in compute (MosaicMode::Compute; block 1x1 for MosaicMode::Off), same rule and
// encode as mosaic.frag, so both paths give the same bytes. A workgroup covers MOSAIC_GROUP_X x
// MOSAIC_GROUP_Y blocks: each thread reads and encodes one block's pixel once (not once per output
// pixel), then stores its block row of the tile with consecutive threads on consecutive pixels
// (coalesced stores). The host sizes the dispatch from the reflected local size.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "mosaic.h"
#include "render/color8.glsl"

layout(local_size_x = MOSAIC_GROUP_X, local_size_y = MOSAIC_GROUP_Y) in;

layout(set = 0, binding = 0) uniform texture2D sceneColor;  // linear light
layout(set = 0, binding = 1) writeonly uniform image2D outputImage;  // UNORM; no format: BGRA works too
layout(push_constant) uniform Push { MosaicPush pc; };

shared vec4 encoded[MOSAIC_GROUP_Y][MOSAIC_GROUP_X];

void main() {
  const ivec2 t = ivec2(gl_LocalInvocationID.xy);
  const ivec2 tile = ivec2(MOSAIC_GROUP_X, MOSAIC_GROUP_Y) * pc.block;  // in pixels
  const ivec2 origin = ivec2(gl_WorkGroupID.xy) * tile;
  const ivec2 mine = origin + t * pc.block;  // top-left pixel of this thread's block
  if (all(lessThan(mine, pc.size)))
    encoded[t.y][t.x] = encode8(vec4(texelFetch(sceneColor, mosaicSource(mine, pc.block, pc.size), 0).rgb, 1.0), true);
  barrier();
  const int endX = min(origin.x + tile.x, pc.size.x), endY = min(mine.y + pc.block.y, pc.size.y);
  for (int x = origin.x + t.x; x < endX; x += MOSAIC_GROUP_X) {
    const vec4 c = encoded[t.y][(x - origin.x) / pc.block.x];
    for (int y = mine.y; y < endY; ++y) imageStore(outputImage, ivec2(x, y), c);
  }
}
