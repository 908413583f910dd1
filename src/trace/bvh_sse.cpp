// The BVH traversal with SSE4.2: eight lanes as two 4-wide registers (the fallback without AVX2).
#define RTR_BVH_ISA sse
#define RTR_BVH_AVX2 0
#include "trace/bvh_traverse.inl"
