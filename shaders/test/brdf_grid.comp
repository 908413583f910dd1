#version 460
// Evaluates the shared BRDF (shaders/shared/brdf.h) on a list of inputs, so a GPU test can compare it
// with the CPU build of the same header. Compile with -I shaders/shared.
#extension GL_GOOGLE_include_directive : require
#include "brdf.h"
#include "brdf_grid.h"

layout(local_size_x = BRDF_GRID_LOCAL_SIZE) in;

layout(std430, set = 0, binding = BRDF_GRID_BINDING_IN) readonly buffer GridIn { BrdfGridInput gridIn[]; };
layout(std430, set = 0, binding = BRDF_GRID_BINDING_OUT) writeonly buffer GridOut { BrdfGridOutput gridOut[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= uint(gridIn.length())) return;
  BrdfGridInput a = gridIn[i];
  int brdf = int(a.params.z);
  BrdfTerms t = brdfTerms(brdf, a.n.xyz, a.v.xyz, a.l.xyz, a.baseColor.rgb, a.params.x, a.params.y);
  vec3 L = shadePbr(brdf, a.n.xyz, a.v.xyz, a.l.xyz, a.lightColor.rgb, a.ambient.rgb, a.baseColor.rgb, a.params.x,
                    a.params.y, a.emissive.rgb);
  BrdfGridOutput o;
  o.DG = vec4(t.D, t.G, 0.0, 0.0);
  o.F = vec4(t.F, 0.0);
  o.diffuse = vec4(t.diffuse, 0.0);
  o.specular = vec4(t.specular, 0.0);
  o.radiance = vec4(L, 0.0);
  gridOut[i] = o;
}
