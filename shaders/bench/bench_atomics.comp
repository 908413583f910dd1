#version 460
// rtr-bench-gpu --only atomics: one 64-bit atomicMin (or plain store) a thread on a visibility-sized
// buffer, in the pattern of specialization constant 0 (bench_atomics.h); the bound of the compute
// rasteriser's per-pixel write (docs/bench/gpu-passes.md).
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_GOOGLE_include_directive : require
#include "bench_atomics.h"

layout(local_size_x = 256) in;
layout(constant_id = 0) const uint kPattern = BENCH_ATOMIC_COHERENT;
layout(set = 0, binding = 0, std430) buffer Words { uint64_t words[]; };
layout(push_constant) uniform Push { BenchAtomicsPush pc; };

void main() {
  const uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
  if (i >= pc.words) return;
  const uint64_t value = (uint64_t(benchAtomicsKey(i)) << 32) | uint64_t(i);
  const bool scattered = kPattern == BENCH_ATOMIC_SCATTERED || kPattern == BENCH_STORE_SCATTERED;
  uint w = i;
  if (scattered) w = uint((uint64_t(i) * uint64_t(pc.stride)) % uint64_t(pc.words));
  if (kPattern == BENCH_ATOMIC_CONTENDED) w = i / pc.contention;
  if (kPattern == BENCH_STORE_COHERENT || kPattern == BENCH_STORE_SCATTERED) words[w] = value;
  else atomicMin(words[w], value);
}
