#pragma once
// One mesh's GPU cluster records, made once in its own space for GpuScene's upload (docs/culling.md):
// level 0 (the mesh's clusters), then the levels above, their level-of-detail records, and a culling tree
// over each level, their roots first. A large mesh's are made on all cores in fixed pieces of records
// (docs/startup.md, "The records of a large mesh"); the bytes are those that appendClusters,
// appendClusterLods (level 0, then above), enclosingSphere and appendClusterTree (render/cull.hpp) make
// one after another, whatever the thread count or the piece size.
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/vec4.hpp>

#include "cluster.h"
#include "scene/grow_array.hpp"
#include "scene/scene.hpp"

namespace rtr::render {

struct MeshRecords {
  uint32_t first = 0, count = 0, level0 = 0, firstLevel = 0, levels = 0, leaves = 0;  // first, firstLevel: GpuScene's
  glm::vec4 sphere{0.0f}, lodSphere{0.0f};  // around the records' culling spheres; their level-of-detail spheres
  std::vector<uint32_t> depths;             // its trees' nodes at each depth
  GrowArray<shader::GpuCluster> clusters;   // count records (GrowArray: first touched by the pieces' threads)
  GrowArray<shader::GpuClusterLod> lods;    // count records, or none (no level-of-detail records)
  std::vector<shader::GpuCullNode> nodes;   // leaves name records, others nodes, both numbered from 0
};

// Records a piece: CULL_LEAF_SIZE * CULL_NODE_CHILDREN^3, so that a piece of a level is a subtree of its
// tree (the 100M temple's statue: about 220 pieces; the 10M one's 23).
constexpr size_t kRecordPiece = size_t(CULL_LEAF_SIZE) * CULL_NODE_CHILDREN * CULL_NODE_CHILDREN * CULL_NODE_CHILDREN;

// The records of `mesh` with CLUSTER_* `flags`, and level-of-detail records where `lods` (some mesh of the
// scene has a hierarchy), on up to `threads` threads (0: all cores) in pieces of `piece` records
// (CULL_LEAF_SIZE times a power of CULL_NODE_CHILDREN). A hierarchy's clusters must list level 0 first, in
// the mesh's clusters' order (as scene.hpp says; Error otherwise).
MeshRecords buildMeshRecords(const Mesh& mesh, uint32_t flags, bool lods, unsigned threads = 0, size_t piece = kRecordPiece);

}  // namespace rtr::render
