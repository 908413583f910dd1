#version 460
// Environment, step 3 for the rough levels: the same lobe as env_specular.comp (GGX D with n = v = r,
// weighted by n.l), summed over every texel of one small source level instead of sampled, so a sun
// leaves no sampling pattern (the blotches that 4096 half vectors per texel only thinned out); exact for
// that level, whose texels are several times smaller than the lobe (EnvironmentMaps picks it).
// The level is read in chunks through shared memory; ENV_SUM_SLICES threads share each output texel,
// each summing a part of every chunk, so that small outputs still fill a GPU.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "env_prefilter.h"

layout(local_size_x = ENV_GROUP, local_size_y = ENV_GROUP, local_size_z = ENV_SUM_SLICES) in;

layout(set = 0, binding = 0) uniform texture2DArray src;  // the source cube's faces
layout(set = 0, binding = 1, rgba16f) writeonly uniform image2DArray dst;
layout(push_constant) uniform Push { EnvPush pc; };

#define CHUNK 256u
#define THREADS (ENV_GROUP * ENV_GROUP * ENV_SUM_SLICES)
shared vec4 texDir[CHUNK];       // direction, solid angle
shared vec3 texRadiance[CHUNK];  // radiance x solid angle
shared vec4 partial[THREADS];

void main() {
  const uvec3 id = uvec3(gl_GlobalInvocationID.xy, gl_WorkGroupID.z);  // z: the face
  const uint slice = gl_LocalInvocationID.z, tid = gl_LocalInvocationIndex;
  const vec3 n = envCubeDir(id.z, (vec2(id.xy) + 0.5) / float(pc.size) * 2.0 - 1.0);
  const float alpha = max(pc.roughness * pc.roughness, BRDF_ALPHA_MIN), a2 = alpha * alpha;
  const uint m = pc.srcSize, total = 6u * m * m;
  vec4 acc = vec4(0.0);  // rgb: radiance x weight, a: weight
  for (uint base = 0u; base < total; base += CHUNK) {
    barrier();  // the chunk before is summed
    for (uint i = tid; i < CHUNK; i += THREADS) {
      const uint t = base + i, f = t / (m * m), x = t % m, y = (t / m) % m;
      const float omega = t < total ? envCubeTexelSolidAngle(x, y, m) : 0.0;
      texDir[i] = vec4(envCubeDir(f, (vec2(x, y) + 0.5) / float(m) * 2.0 - 1.0), omega);
      texRadiance[i] = t < total ? texelFetch(src, ivec3(x, y, f), int(pc.level)).rgb * omega : vec3(0.0);
    }
    barrier();
    for (uint i = slice; i < CHUNK; i += ENV_SUM_SLICES) {
      const vec4 d = texDir[i];
      const float nl = dot(n, d.xyz);
      // GGX D at n.h² = (1 + n.l) / 2 (h halfway between n and l), times n.l and the texel's solid angle.
      const float k = (1.0 + nl) * 0.5 * (a2 - 1.0) + 1.0;
      const float w = nl > 0.0 ? a2 / (k * k) * nl : 0.0;
      acc += vec4(texRadiance[i], d.w) * w;
    }
  }
  partial[tid] = acc;
  barrier();
  if (slice != 0u || id.x >= pc.size || id.y >= pc.size) return;
  for (uint s = 1u; s < ENV_SUM_SLICES; ++s) acc += partial[tid + s * ENV_GROUP * ENV_GROUP];
  const vec3 c = acc.a > 0.0 ? acc.rgb / acc.a : vec3(0.0);
  imageStore(dst, ivec3(id), vec4(min(c, vec3(65000.0)), 1.0));
}
