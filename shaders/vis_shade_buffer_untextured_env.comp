#version 460
#extension GL_GOOGLE_include_directive : require
#define HAS_TEXCOORDS 0
#define VIS_BUFFER 1
#define HAS_ENV 1
#include "vis_shade.glsl"
