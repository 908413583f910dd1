// The BVH traversal with AVX2 and FMA (this file alone is compiled for them; bvh.cpp picks it at run time).
#define RTR_BVH_ISA avx2
#define RTR_BVH_AVX2 1
#include "trace/bvh_traverse.inl"
