#version 460
#extension GL_GOOGLE_include_directive : require
// RGBA8 outputs: a declared format lets the driver skip the run-time format conversion of the store.
#define MOSAIC_OUTPUT_LAYOUT layout(rgba8)
#include "render/mosaic_comp.glsl"
