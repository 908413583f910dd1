#pragma once
// .rtrscene version 6's CLOD chunk: the meshes' cluster hierarchies (scene/cluster_lod.hpp). Byte table:
// docs/rtrscene-format.md. rtrscene.cpp frames it (tag, size, pad) and calls these for the body.
#include <cstdint>
#include <string>
#include <vector>

#include "scene/binio.hpp"
#include "scene/scene.hpp"

namespace rtr {

// Whether any mesh holds a hierarchy (a chunk to write).
bool hasClusterLods(const Scene& scene);
// The chunk's body (16-byte aligned from its start).
void writeClusterLods(ByteWriter& w, const Scene& scene);

// Reading, in two steps so that the hierarchies are read on all cores together with the meshes' arrays
// (rtrscene.cpp's readArrays): first the body's mesh records, then pieces of each hierarchy.
// Where one mesh's hierarchy lies in the file.
struct LodLayout {
  uint32_t mesh = 0, count = 0, indexCount = 0;
  size_t at = 0, clustersAt = 0, indicesAt = 0;  // its mesh record, cluster records and indices
};
// A fault found by a piece of a parallel read; of several, the one at the lowest offset is reported, so
// that the message does not depend on the thread count.
struct ReadFault {
  size_t at = SIZE_MAX;
  std::string what;
};
// Reads the mesh records of a body of `size` bytes at r.pos() (the meshes' records already read: their
// vertex and cluster counts) into `out`, checking their counts against the meshes and the body (a fault
// thrown naming its offset; `out` holds the records before it), setting each mesh's lod.levels. Its
// records (once lod.clusters holds `count`) and indices are read by the two below.
void readClusterLodLayout(ByteReader& r, uint64_t size, Scene& scene, std::vector<LodLayout>& out);
// Records [first, end) of a hierarchy read into `out` (null: m.lod.clusters is a view of them) and checked
// on their own and against the record before (levels in order, triangles tiling the hierarchy's; level 0
// the mesh's own clusters, read from the file at `ownClustersAt`; its `triangles` from its record: its
// arrays may be being copied meanwhile); the last piece checks that they hold all its triangles.
void readLodClusters(const Mesh& m, LodCluster* out, const LodLayout& l, const uint8_t* file, size_t ownClustersAt,
                     uint32_t triangles, size_t first, size_t end);
// Indices [first, end) of a hierarchy checked against the mesh's `vertices` (read from the file).
void checkLodIndices(const LodLayout& l, const uint8_t* file, size_t vertices, size_t first, size_t end);

}  // namespace rtr
