#version 460
// The fused depth pyramid (hiz_fused.glsl) from the compute rasteriser's 64-bit visibility buffer (depth
// bits in each pixel's high word; raster.h), as hiz_buffer.comp reads it: an empty pixel (all ones, a NaN
// as float) counts as the far plane.
#extension GL_GOOGLE_include_directive : require
#include "render/hiz_fused.glsl"

layout(set = 0, binding = 0, std430) readonly buffer Vis { uvec2 vis[]; };  // (low, high) a pixel

float loadSource(ivec2 p) {
  const uint bits = vis[uint(p.y) * pc.width + uint(p.x)].y;
  return bits == ~0u ? 1.0f : uintBitsToFloat(bits);
}
