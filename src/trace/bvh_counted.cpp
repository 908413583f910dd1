// The BVH traversal that counts what it does (BvhCounters): the SSE code with counters, run only while
// Bvh::setCounting(true) (tests, bench-trace), so the timed traversals carry none. Counts do not depend on
// the instruction set: every build takes the same decisions.
#define RTR_BVH_ISA counted
#define RTR_BVH_AVX2 0
#define RTR_BVH_COUNT 1
#include "trace/bvh_traverse.inl"
