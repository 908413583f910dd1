#version 460
#extension GL_GOOGLE_include_directive : require
#define HAS_TEXCOORDS 1
#define ALPHA_MASK 0
#define BLEND 1
#include "pbr_frag.glsl"
