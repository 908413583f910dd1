// rtr-bench-gpu's atomics micro-benchmark (`--only atomics`, shaders/bench/bench_atomics.comp): what a
// thread writes and where, shared by the shader and the CPU check of the result.
#ifndef RTR_SHADERS_SHARED_BENCH_ATOMICS_H
#define RTR_SHADERS_SHARED_BENCH_ATOMICS_H

#include "shared.h"
#ifdef __cplusplus
#include <cstdint>
namespace rtr::shader {
typedef uint32_t uint;
#endif

// The pattern (the shader's specialization constant 0): thread i writes word
#define BENCH_ATOMIC_COHERENT 0u   // i, with atomicMin (neighbouring threads, neighbouring words)
#define BENCH_ATOMIC_SCATTERED 1u  // i * stride mod words (a permutation: every word once, stride apart)
#define BENCH_ATOMIC_CONTENDED 2u  // i / contention (that many threads of a warp on one word)
#define BENCH_STORE_COHERENT 3u    // i, with a plain store
#define BENCH_STORE_SCATTERED 4u   // i * stride mod words, with a plain store

struct BenchAtomicsPush {
  uint words;       // threads, and words of the buffer
  uint stride;      // coprime with words
  uint contention;  // threads a word (BENCH_ATOMIC_CONTENDED)
  uint pad;
};

// The high word of thread i's value (its low word is i), as a visibility word's depth: not ordered by i,
// so which thread of a contended word wins depends on the data.
RTR_FN uint benchAtomicsKey(uint i) {
  uint h = i * 0x9E3779B1u;
  h ^= h >> 15u;
  h *= 0x85EBCA77u;
  return h ^ (h >> 13u);
}

#ifdef __cplusplus
}  // namespace rtr::shader
#endif
#endif
