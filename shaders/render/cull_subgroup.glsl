// The culling pass's counters and lists take one atomic per subgroup, not one per thread: thousands of
// threads adding to the same few words of CullCounts wait on each other at the memory's atomic unit.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require

// Adds each active invocation's `n` to `counter` with one atomic.
#define CULL_COUNT(counter, n)                                 \
  {                                                            \
    const uint total_ = subgroupAdd(n);                        \
    if (total_ > 0u && subgroupElect()) atomicAdd(counter, total_); \
  }

// Reserves each active invocation's `n` entries after `counter`: `at` gets where its own start, `last`
// (elected invocation only, else 0xFFFFFFFF) the last entry the subgroup reserved, for the dispatch.
#define CULL_RESERVE(counter, n, at, last)                     \
  {                                                            \
    const uint total_ = subgroupAdd(n);                        \
    uint base_ = 0u;                                           \
    last = 0xFFFFFFFFu;                                        \
    if (total_ > 0u && subgroupElect()) {                      \
      base_ = atomicAdd(counter, total_);                      \
      last = base_ + total_ - 1u;                              \
    }                                                          \
    at = subgroupBroadcastFirst(base_) + subgroupExclusiveAdd(n); \
  }
