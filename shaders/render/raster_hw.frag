#version 460
// The compute rasteriser's hand-off, fragment stage: the same alpha test as vis.frag, the same
// back-face rule as the visibility pipelines, then the same 64-bit atomicMin as raster.comp.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_nonuniform_qualifier : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#define RASTER_LIST_ACCESS readonly
#include "raster_fetch.glsl"

layout(set = 0, binding = 8, std430) readonly buffer Materials { GpuMaterial materials[]; };
layout(set = 1, binding = 0) uniform sampler2D textures[];

layout(location = 0) flat in uint inId;
layout(location = 1) flat in uint inMaterial;
layout(location = 2) flat in uint inFlags;
layout(location = 3) in vec2 inTexcoord;

void main() {
  if ((inFlags & CLUSTER_ALPHA_MASKED) != 0u) {
    const GpuMaterial m = materials[inMaterial];
    if (m.textures.w != NO_TEXTURE) {
      const vec2 uv = maskTexcoord(m, inTexcoord);  // set 0's texcoords
      if (maskCuts(m, texture(textures[nonuniformEXT(m.textures.w)], uv, frame.params.y))) discard;
    }
  }
  const bool front = gl_FrontFacing != ((inFlags & CLUSTER_MIRRORED) != 0u);  // the pipeline's front is counter-clockwise
  if (!front && (inFlags & CLUSTER_DOUBLE_SIDED) == 0u) discard;
  atomicMin(vis[uint(gl_FragCoord.y) * pc.width + uint(gl_FragCoord.x)], packVis(gl_FragCoord.z, inId));
}
