#include "render/mesh_records.hpp"

#include <algorithm>
#include <string>

#include <glm/glm.hpp>

#include "core/bounds.hpp"
#include "core/error.hpp"
#include "core/parallel.hpp"
#include "render/cull.hpp"

namespace rtr::render {

// Two rounds over fixed pieces, then a short join on the calling thread:
//  1. each piece of records: its records and level-of-detail records, the boxes of their spheres, and
//     where a level above level 0 starts in it;
//  2. each piece of records: its spheres' farthest reach from the joined boxes' centres; and each piece
//     of each level's run of records: its subtree (leaves and the node layers up to one node), or the
//     whole tree of a run no longer than a piece;
//  3. the mesh's spheres; each run's subtrees side by side, the layers above them, the trees stored.
// Boxes and reaches are minima and maxima, joined in piece order, so the bits are enclosingSphere's; a
// piece of a run is a whole subtree of appendClusterTree's (its records a multiple of a subtree's).
MeshRecords buildMeshRecords(const Mesh& m, uint32_t flags, bool lods, unsigned threads, size_t piece) {
  size_t nodeLayers = 0;  // of a piece's subtree
  size_t subtree = CULL_LEAF_SIZE;
  for (; subtree < piece; subtree *= CULL_NODE_CHILDREN) ++nodeLayers;
  if (subtree != piece)
    throw Error("mesh records: pieces of " + std::to_string(piece) + " records, not " + std::to_string(CULL_LEAF_SIZE) +
                " times a power of " + std::to_string(CULL_NODE_CHILDREN));
  const bool hierarchy = lods && m.lod.levels > 0;
  const uint32_t triangles = uint32_t(m.indices.size() / 3);
  const size_t own = m.clusters.empty() ? (triangles + CLUSTER_MAX_TRIANGLES - 1) / CLUSTER_MAX_TRIANGLES : m.clusters.size();
  auto unordered = [&] { return Error("a mesh's hierarchy does not list its " + std::to_string(own) + " clusters first"); };
  if (hierarchy && (m.clusters.empty() || m.lod.clusters.size() < own)) throw unordered();
  const size_t count = hierarchy ? m.lod.clusters.size() : own;
  MeshRecords r;
  r.count = uint32_t(count), r.level0 = uint32_t(own);
  r.clusters.resize(count);
  if (lods) r.lods.resize(count);
  const unsigned use = count > piece ? threads : 1;  // a small mesh on its own thread (no threads started)

  // 1. Records, as appendClusters and appendClusterLods make them (identity, instance 0).
  struct Piece {
    Bounds box, lodBox;
    float reach = 0.0f, lodReach = 0.0f;
    std::vector<uint32_t> starts;  // records that begin a level above level 0
  };
  const size_t pieces = (count + piece - 1) / piece;
  std::vector<Piece> parts(pieces);
  parallelFor(pieces, use, [&](size_t k) {
    Piece& pc = parts[k];
    for (size_t i = k * piece; i < std::min(count, (k + 1) * piece); ++i) {
      shader::GpuCluster& c = r.clusters[i];
      if (i < own && !m.clusters.empty()) {
        c = clusterRecord(m.clusters[i], 0, flags);
      } else if (i < own) {  // no clusters: runs of triangles
        c = triangleRunRecord(m, uint32_t(i * CLUSTER_MAX_TRIANGLES), 0, flags);
      } else {
        const LodCluster& s = m.lod.clusters[i];
        if (s.level == 0) throw unordered();
        c = clusterRecord(s, 0, flags);
        if (i == own || s.level != m.lod.clusters[i - 1].level) pc.starts.push_back(uint32_t(i));
      }
      extendBySphere(pc.box, c.sphere);
      if (!lods) continue;
      shader::GpuClusterLod& l = r.lods[i];
      if (hierarchy) {
        const LodCluster& s = m.lod.clusters[i];
        if (i < own && s.level != 0) throw unordered();
        l = lodRecord(s);
      } else {
        l = alwaysInCut(c.sphere);
      }
      extendBySphere(pc.lodBox, l.sphere);
      if (l.error.y < shader::LOD_ERROR_INFINITE) extendBySphere(pc.lodBox, l.parentSphere);
    }
  });
  Bounds box, lodBox;
  std::vector<glm::uvec2> runs{{0, uint32_t(own)}};  // level 0, then the levels above in the hierarchy's order
  for (const Piece& pc : parts) {
    box.extend(pc.box), lodBox.extend(pc.lodBox);
    for (uint32_t s : pc.starts) runs.push_back({s, 0});
  }
  for (size_t l = 1; l < runs.size(); ++l) runs[l].y = (l + 1 < runs.size() ? runs[l + 1].x : uint32_t(count)) - runs[l].x;

  // 2. The spheres' reaches; the runs' subtrees (a run of one piece: its whole tree).
  struct TreePiece {
    uint32_t first, count;
    bool whole;
  };
  std::vector<TreePiece> treePieces;
  std::vector<size_t> firstPiece;  // per run, then the end
  for (const glm::uvec2& run : runs) {
    firstPiece.push_back(treePieces.size());
    const size_t n = std::max<size_t>(1, (run.y + piece - 1) / piece);
    for (size_t p = 0; p < n; ++p)
      treePieces.push_back({uint32_t(run.x + p * piece), uint32_t(std::min<size_t>(piece, run.y - p * piece)), n == 1});
  }
  firstPiece.push_back(treePieces.size());
  std::vector<ClusterTreeLayers> subtrees(treePieces.size());
  parallelFor(treePieces.size() + pieces, use, [&](size_t t) {
    if (t < treePieces.size()) {
      const TreePiece& tp = treePieces[t];
      subtrees[t] = clusterTreeLayers(r.clusters, r.lods, tp.first, tp.count, tp.whole ? SIZE_MAX : nodeLayers);
      return;
    }
    Piece& pc = parts[t - treePieces.size()];
    const size_t k = t - treePieces.size();
    for (size_t i = k * piece; i < std::min(count, (k + 1) * piece); ++i) {
      pc.reach = std::max(pc.reach, sphereReach(box, r.clusters[i].sphere));
      if (!lods) continue;
      const shader::GpuClusterLod& l = r.lods[i];
      pc.lodReach = std::max(pc.lodReach, sphereReach(lodBox, l.sphere));
      if (l.error.y < shader::LOD_ERROR_INFINITE) pc.lodReach = std::max(pc.lodReach, sphereReach(lodBox, l.parentSphere));
    }
  });

  // 3. The join.
  float reach = 0.0f, lodReach = 0.0f;
  for (const Piece& pc : parts) reach = std::max(reach, pc.reach), lodReach = std::max(lodReach, pc.lodReach);
  r.sphere = enclosingSphere(box, reach);
  r.lodSphere = lods && count ? enclosingSphere(lodBox, lodReach) : r.sphere;
  size_t made = 0;
  for (const ClusterTreeLayers& layers : subtrees)
    for (const auto& layer : layers) made += layer.size();
  r.levels = uint32_t(runs.size());
  r.nodes.reserve(made + made / 4 + runs.size());  // the layers above the subtrees: about a seventh more at most
  r.nodes.resize(runs.size());
  for (size_t l = 0; l < runs.size(); ++l) {
    if (firstPiece[l + 1] - firstPiece[l] == 1) {
      r.leaves += storeClusterTree(subtrees[firstPiece[l]], uint32_t(l), r.nodes, r.depths);
      continue;
    }
    // The subtrees' layers side by side (a node's first renumbered past the earlier subtrees' layer below
    // it), then the layers above them.
    ClusterTreeLayers layers(nodeLayers + 1);
    for (size_t i = 0; i <= nodeLayers; ++i) {
      size_t size = 0;
      for (size_t p = firstPiece[l]; p < firstPiece[l + 1]; ++p) size += subtrees[p][i].size();
      layers[i].reserve(size);
      uint32_t below = 0;
      for (size_t p = firstPiece[l]; p < firstPiece[l + 1]; ++p) {
        for (shader::GpuCullNode node : subtrees[p][i]) {
          if (i > 0) node.first += below;
          layers[i].push_back(node);
        }
        if (i > 0) below += uint32_t(subtrees[p][i - 1].size());
      }
    }
    while (layers.back().size() > 1) addClusterTreeLayer(layers);
    r.leaves += storeClusterTree(layers, uint32_t(l), r.nodes, r.depths);
  }
  return r;
}

}  // namespace rtr::render
