#version 460
// Mosaic post-process in compute (MosaicMode::Compute; block 1x1 for MosaicMode::Off), same rule and
// encode as mosaic.frag, so both paths give the same bytes. A workgroup covers MOSAIC_GROUP blocks of
// one block row: each thread reads and encodes one block's pixel once (not once per output pixel), then
// the group writes the tile row by row, consecutive threads on consecutive pixels (coalesced stores).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "mosaic.h"
#include "render/color8.glsl"

layout(local_size_x = MOSAIC_GROUP) in;

layout(set = 0, binding = 0) uniform texture2D sceneColor;  // linear light
layout(set = 0, binding = 1) writeonly uniform image2D outputImage;  // UNORM; no format: BGRA works too
layout(push_constant) uniform Push { MosaicPush pc; };

shared vec4 encoded[MOSAIC_GROUP];

void main() {
  const int t = int(gl_LocalInvocationID.x);
  const ivec2 origin = ivec2(gl_WorkGroupID.xy) * ivec2(MOSAIC_GROUP, 1) * pc.block;  // the tile's top-left pixel
  const ivec2 mine = origin + ivec2(t * pc.block.x, 0);  // top-left pixel of this thread's block
  if (mine.x < pc.size.x)
    encoded[t] = encode8(vec4(texelFetch(sceneColor, mosaicSource(mine, pc.block, pc.size), 0).rgb, 1.0), true);
  barrier();
  const ivec2 end = min(origin + ivec2(MOSAIC_GROUP, 1) * pc.block, pc.size);
  for (int x = origin.x + t; x < end.x; x += MOSAIC_GROUP) {
    const vec4 c = encoded[(x - origin.x) / pc.block.x];
    for (int y = origin.y; y < end.y; ++y) imageStore(outputImage, ivec2(x, y), c);
  }
}
