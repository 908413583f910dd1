#version 460
#extension GL_GOOGLE_include_directive : require
#define ALPHA_MASK 0
#include "vis_frag.glsl"
