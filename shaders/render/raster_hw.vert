#version 460
// The compute rasteriser's hand-off (raster.comp): triangles it leaves to the hardware (crossing w = 0,
// outside the guard band), pulled from the list by gl_VertexIndex; the hardware clips them.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#define RASTER_VIS_ACCESS readonly
#define RASTER_LIST_ACCESS readonly
#include "raster_fetch.glsl"

layout(set = 0, binding = 9, std430) readonly buffer Texcoords { vec2 texcoords[]; };  // any buffer if untextured

layout(location = 0) flat out uint outId;
layout(location = 1) flat out uint outMaterial;  // NO_TEXTURE: no alpha test
layout(location = 2) flat out uint outFlags;     // CLUSTER_*
layout(location = 3) out vec2 outTexcoord;

void main() {
  if (uint(gl_VertexIndex) / 3u >= pc.handOffCapacity) {  // dropped (raster.h): a point, no fragment
    gl_Position = vec4(0.0, 0.0, 2.0, 1.0);
    outId = 0u, outMaterial = NO_TEXTURE, outFlags = 0u, outTexcoord = vec2(0.0);
    return;
  }
  const uint entry = hwTriangles[gl_VertexIndex / 3];
  const GpuCluster c = listedCluster(entry >> RASTER_LOCAL_BITS);
  const GpuInstance inst = placedInstance(c.instance);
  const GpuDraw d = draws[inst.info.x];
  const uint local = entry & ((1u << RASTER_LOCAL_BITS) - 1u);
  const uint v = triangleVertices(c, d, local)[gl_VertexIndex % 3];
  outId = inst.info.z + c.firstTriangle + local;
  outMaterial = d.material;
  outFlags = c.flags;
  outTexcoord = (c.flags & CLUSTER_ALPHA_MASKED) != 0u ? texcoords[v] : vec2(0.0);
  gl_Position = clipPosition(inst, v);
}
