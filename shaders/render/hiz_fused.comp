#version 460
// The fused depth pyramid (hiz_fused.glsl) from a sampled view whose .r is depth: the depth image (a D32
// view or an R32F image) for level 0, or the level below the dispatch's first one.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "render/hiz_fused.glsl"

layout(set = 0, binding = 0) uniform texture2D src;

float loadSource(ivec2 p) { return texelFetch(src, p, 0).r; }
