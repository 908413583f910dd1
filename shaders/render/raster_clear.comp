#version 460
// Compute rasteriser, first pass: every pixel to RASTER_CLEAR (depth bits and id all ones) and the
// hand-off, tile, medium and clipping lists to none. Where the shading pass of the frame before cleared the
// pixels (ComputeRaster::shadingCleared), it runs as one workgroup: the lists, and the first pixels again.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#include "raster_fetch.glsl"

layout(local_size_x = RASTER_CLEAR_GROUP) in;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i == 0u) vertexCount = 0u, instanceCount = 1u, firstVertex = 0u, firstInstance = 0u, largeCount = 0u, largeFirst = 0u,
                 largeTriCount = 0u, mediumFound = 0ul, mediumFirst = 0ul, mediumStored = ~0ul, clipGroupsX = 0u, clipGroupsY = RASTER_CLIP_PIECES, clipGroupsZ = 1u, clipCount = 0u, clipFirst = 0u;
  if (i < pc.width * pc.height) vis[i] = ~uint64_t(0);
}
