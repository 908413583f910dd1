#version 460
// Environment, step 3: one level of the GGX-prefiltered specular cube (split sum, with n = v = r) whose
// lobe is narrow (env_specular_sum.comp sums the wide ones over a small source level instead): the
// radiance around each texel's direction weighted by the lobe of the level's roughness and n.l, from
// half vectors drawn from D. Each sample reads the source cube at the mip whose texels cover about the
// solid angle the sample stands for (filtered importance sampling), so a bright texel cannot show up as
// single-sample fireflies. Results are clamped to half float's range.
#extension GL_GOOGLE_include_directive : require
#include "env_prefilter.h"

layout(local_size_x = ENV_GROUP, local_size_y = ENV_GROUP) in;

layout(set = 0, binding = 0) uniform samplerCube src;
layout(set = 0, binding = 1, rgba16f) writeonly uniform image2DArray dst;
layout(push_constant) uniform Push { EnvPush pc; };

void main() {
  const uvec3 id = gl_GlobalInvocationID;
  if (id.x >= pc.size || id.y >= pc.size) return;
  const vec3 n = envCubeDir(id.z, (vec2(id.xy) + 0.5) / float(pc.size) * 2.0 - 1.0);
  const float alpha = max(pc.roughness * pc.roughness, BRDF_ALPHA_MIN);
  const vec3 t = envTangent(n), b = cross(n, t);
  // Never finer than this level's own texels: a texel averages its footprint (roughness 0 too).
  const float lodMin = 0.5 * log2(4.0 * BRDF_PI / (6.0 * float(pc.size * pc.size)) / pc.srcTexelSolidAngle);
  // Never coarser than faces of 8² texels: a cube's coarsest levels (1², 2², 4² a face) are bilinear
  // within each face only, and a bright texel there paints the lobe with the faces' outlines.
  const float lodMax = max(float(pc.srcLevels) - 4.0, 0.0);
  vec3 sum = vec3(0.0);
  float weight = 0.0;
  for (uint i = 0u; i < pc.samples; ++i) {
    const vec3 hl = envGgxHalf(envHammersley(i, pc.samples), alpha);
    const vec3 h = t * hl.x + b * hl.y + n * hl.z;
    const vec3 l = 2.0 * dot(n, h) * h - n;
    const float nl = dot(n, l);
    if (nl <= 0.0) continue;
    // pdf(l) = D n.h / (4 v.h) = D / 4 with v = n; the sample stands for 1 / (N pdf) steradians.
    const float pdf = brdfGgxD(vec3(0.0, 0.0, 1.0), hl, alpha) * 0.25;
    const float omega = 1.0 / (float(pc.samples) * pdf + 1e-20);
    const float lod = clamp(max(0.5 * log2(omega / pc.srcTexelSolidAngle), lodMin), 0.0, lodMax);
    sum += textureLod(src, l, lod).rgb * nl;
    weight += nl;
  }
  const vec3 c = weight > 0.0 ? sum / weight : textureLod(src, n, lodMin).rgb;
  imageStore(dst, ivec3(id), vec4(min(c, vec3(65000.0)), 1.0));
}
