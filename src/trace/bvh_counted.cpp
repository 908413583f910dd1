// The BVH traversal that counts what it does (BvhCounters): the AVX2 code with counters, run only while
// Bvh::setCounting(true) (tests, bench-trace), so the timed traversals carry none. The AVX-512 build
// takes the same decisions (the SSE build has no packet interval test).
#define RTR_BVH_ISA counted
#define RTR_BVH_AVX2 1
#define RTR_BVH_COUNT 1
#include "trace/bvh_traverse.inl"
