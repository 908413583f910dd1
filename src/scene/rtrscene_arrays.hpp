#pragma once
// .rtrscene's meshes (docs/rtrscene-format.md): where each one's arrays lie in the file (found by the
// decoder's pass over the records), and the second pass, which copies them out of the file and checks
// every value, index and cluster, the hierarchies' (CLOD) too, in pieces on all cores.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "scene/binio.hpp"
#include "scene/rtrscene_lod.hpp"
#include "scene/scene.hpp"

namespace rtr::rtrscene {

constexpr uint32_t kHasNormals = 1u << 0, kHasTexcoords = 1u << 1, kIndex16 = 1u << 2;      // mesh flags
constexpr uint32_t kHasTexcoords1 = 1u << 3, kHasTangents = 1u << 4, kHasColors = 1u << 5;  // version 5

// Where a mesh's arrays and clusters lie in the file: found by the first pass over the records, copied out
// and checked by the second, on all cores.
enum Stream : uint8_t {
  kPositions,
  kNormals,
  kTexcoords,
  kTexcoords1,
  kTangents,
  kColors,
  kIndices,
  kClusters,
  kLodClusters,
  kLodIndices
};
constexpr size_t kVertexStreams = kIndices;  // the per-vertex arrays, in file order
constexpr size_t kVertexSize[kVertexStreams] = {12, 12, 8, 8, 16, 16};
constexpr uint32_t kStreamFlag[kVertexStreams] = {0, kHasNormals, kHasTexcoords, kHasTexcoords1, kHasTangents, kHasColors};
constexpr const char* kStreamName[kVertexStreams] = {"positions", "normals", "texcoords", "texcoords1", "tangents", "colors"};

struct MeshLayout {
  uint32_t flags = 0, vertices = 0, indices = 0, clusters = 0;
  size_t at[kVertexStreams] = {}, indexAt = 0, clusterHeaderAt = 0, clusterAt = 0;
  size_t count(Stream s) const { return s == kIndices ? indices : s == kPositions || (flags & kStreamFlag[s]) ? vertices : 0; }
  size_t elementSize(Stream s) const { return s == kIndices ? (flags & kIndex16 ? 2 : 4) : kVertexSize[s]; }
};

inline std::string meshName(uint32_t i) { return "mesh " + std::to_string(i); }

// A mesh's clusters (their count known from its record, in the first pass), a view of the file's records
// where `owner` keeps the file (rtrscene_arrays.cpp says when), else a vector of that size, filled by
// readArrays once checked.
void placeClusters(Mesh& m, const MeshLayout& l, const uint8_t* file, const std::shared_ptr<const void>& owner);

// The second pass: every array copied out of the file, or made a view of it where `owner` keeps the file
// and its bytes are the array's, and every value, index and cluster checked (reading the file), the
// hierarchies' (`lods`, CLOD) too, in pieces on `threads` threads, biggest first.
void readArrays(std::span<const uint8_t> bytes, Scene& scene, const std::vector<MeshLayout>& layout,
                const std::vector<LodLayout>& lods, unsigned threads, const ByteReader& r,
                const std::shared_ptr<const void>& owner);

}  // namespace rtr::rtrscene
