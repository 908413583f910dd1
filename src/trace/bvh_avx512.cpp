// The BVH traversal with AVX-512VL: the AVX2 code, compiled with 32 vector registers and integer min/max
// in the box test (this file alone is compiled for them; bvh.cpp picks it at run time).
#define RTR_BVH_ISA avx512
#define RTR_BVH_AVX2 1
#define RTR_BVH_INT_MINMAX 1
#include "trace/bvh_traverse.inl"
