#version 460
#extension GL_GOOGLE_include_directive : require
#define ALPHA_MASK 1
#include "vis_vert.glsl"
