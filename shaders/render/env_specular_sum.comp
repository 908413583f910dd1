#version 460
// Environment, step 3 for all but the sharpest levels: the same lobe as env_specular.comp (GGX D with
// n = v = r, weighted by n.l), summed over source texels instead of sampled, so a sun leaves no sampling
// pattern (the blotches that 512-4096 half vectors per texel only thinned out). The sphere is cut into
// tiles of 2x2 texels of the 16²-a-face level; each tile within nearAngle (plus the tile's and the
// workgroup's own radii) of the workgroup's direction is summed over its texels of the fine level
// (pc.srcSize a face, whose texels are several times smaller than the lobe: EnvironmentMaps picks it),
// the others over their 4 coarse texels, which are means of the fine ones: every texel of the sphere
// counts once, the lobe's peak at the fine level's resolution, its tail at the coarse one's; tiles behind
// every output texel's hemisphere of the workgroup (weight 0) are not read.
// Entries are gathered in a fixed order into shared memory and summed chunk by chunk; ENV_SUM_SLICES
// threads share each output texel, each summing a part of every chunk, so that small outputs still fill
// a GPU.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "env_prefilter.h"

layout(local_size_x = ENV_GROUP, local_size_y = ENV_GROUP, local_size_z = ENV_SUM_SLICES) in;

layout(set = 0, binding = 0) uniform texture2DArray src;  // the source cube's faces
layout(set = 0, binding = 1, rgba16f) writeonly uniform image2DArray dst;
layout(push_constant) uniform Push { EnvPush pc; };

#define COARSE 16u  // face size of the coarse level
#define TILES 8u    // tiles per face side (2x2 coarse texels each)
#define CHUNK 256u  // entries summed at a time
#define THREADS (ENV_GROUP * ENV_GROUP * ENV_SUM_SLICES)
shared vec4 texDir[CHUNK];       // direction, solid angle
shared vec3 texRadiance[CHUNK];  // radiance x solid angle
shared vec4 partial[THREADS];
shared uint kind[6u * TILES * TILES];  // of each tile: 0 behind every texel's hemisphere, 1 coarse, 2 fine

vec3 faceDir(uint f, vec2 texel, float size) { return envCubeDir(f, texel / size * 2.0 - 1.0); }

// The largest angle between `centre` and the corners of the square [lo, hi]² of face f (in texels of a
// face `size` wide): the square's angular radius about it (the faces are convex, the corners farthest).
float radius(vec3 centre, uint f, vec2 lo, vec2 hi, float size) {
  float c = 1.0;
  for (uint k = 0u; k < 4u; ++k)
    c = min(c, dot(centre, faceDir(f, vec2((k & 1u) != 0u ? hi.x : lo.x, (k & 2u) != 0u ? hi.y : lo.y), size)));
  return acos(clamp(c, -1.0, 1.0));
}

void main() {
  const uvec3 id = uvec3(gl_GlobalInvocationID.xy, gl_WorkGroupID.z);  // z: the face
  const uint slice = gl_LocalInvocationID.z, tid = gl_LocalInvocationIndex;
  const vec3 n = faceDir(id.z, vec2(id.xy) + 0.5, float(pc.size));
  const float alpha = max(pc.roughness * pc.roughness, BRDF_ALPHA_MIN), a2 = alpha * alpha;

  // Which tiles this workgroup reads at the fine level, and which not at all (n.l <= 0: weight 0).
  const vec2 wlo = vec2(gl_WorkGroupID.xy * ENV_GROUP), whi = min(wlo + float(ENV_GROUP), vec2(pc.size));
  const vec3 wc = faceDir(id.z, 0.5 * (wlo + whi), float(pc.size));
  const float wr = radius(wc, id.z, wlo, whi, float(pc.size));
  for (uint i = tid; i < 6u * TILES * TILES; i += THREADS) {
    const uint f = i / (TILES * TILES), t = i % (TILES * TILES);
    const vec2 tlo = vec2(t % TILES, t / TILES), thi = tlo + 1.0;
    const vec3 tc = faceDir(f, tlo + 0.5, float(TILES));
    const float tr = radius(tc, f, tlo, thi, float(TILES)), apart = acos(clamp(dot(wc, tc), -1.0, 1.0));
    kind[i] = apart >= 0.5 * BRDF_PI + wr + tr ? 0u : pc.srcSize > COARSE && apart < pc.nearAngle + wr + tr ? 2u : 1u;
  }
  barrier();

  const uint per = pc.srcSize / TILES;  // a tile's fine texels a side
  const uint coarseLevel = pc.level + uint(findMSB(pc.srcSize / COARSE));
  vec4 acc = vec4(0.0);  // rgb: radiance x weight, a: weight
  uint fill = 0u;        // the same in every thread: `kind` is shared
  for (uint tile = 0u; tile <= 6u * TILES * TILES; ++tile) {
    const bool last = tile == 6u * TILES * TILES, isFine = !last && kind[tile] == 2u;
    const uint side = last || kind[tile] == 0u ? 0u : isFine ? per : COARSE / TILES, count = side * side;
    if (last || fill + count > CHUNK) {  // sum what is gathered
      barrier();
      for (uint i = slice; i < fill; i += ENV_SUM_SLICES) {
        const vec4 d = texDir[i];
        const float nl = dot(n, d.xyz);
        // GGX D at n.h² = (1 + n.l) / 2 (h halfway between n and l), times n.l and the texel's solid angle.
        const float k = (1.0 + nl) * 0.5 * (a2 - 1.0) + 1.0;
        const float w = nl > 0.0 ? a2 / (k * k) * nl : 0.0;
        acc += vec4(texRadiance[i], d.w) * w;
      }
      barrier();
      fill = 0u;
    }
    if (last) break;
    const uint f = tile / (TILES * TILES), t = tile % (TILES * TILES), size = side * TILES;
    const uvec2 origin = uvec2(t % TILES, t / TILES) * side;
    for (uint i = tid; i < count; i += THREADS) {
      const uvec2 xy = origin + uvec2(i % side, i / side);
      const float omega = envCubeTexelSolidAngle(xy.x, xy.y, size);
      texDir[fill + i] = vec4(faceDir(f, vec2(xy) + 0.5, float(size)), omega);
      texRadiance[fill + i] = texelFetch(src, ivec3(xy, f), int(isFine ? pc.level : coarseLevel)).rgb * omega;
    }
    fill += count;
  }
  partial[tid] = acc;
  barrier();
  if (slice != 0u || id.x >= pc.size || id.y >= pc.size) return;
  for (uint s = 1u; s < ENV_SUM_SLICES; ++s) acc += partial[tid + s * ENV_GROUP * ENV_GROUP];
  const vec3 c = acc.a > 0.0 ? acc.rgb / acc.a : vec3(0.0);
  imageStore(dst, ivec3(id), vec4(min(c, vec3(65000.0)), 1.0));
}
