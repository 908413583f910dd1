#version 460
#extension GL_GOOGLE_include_directive : require
// Any UNORM output (BGRA swapchains too): the store has no format qualifier.
#define MOSAIC_OUTPUT_LAYOUT
#include "render/mosaic_comp.glsl"
