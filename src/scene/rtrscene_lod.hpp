#pragma once
// .rtrscene version 6's CLOD chunk: the meshes' cluster hierarchies (scene/cluster_lod.hpp). Byte table:
// docs/rtrscene-format.md. rtrscene.cpp frames it (tag, size, pad) and calls these for the body.
#include "scene/binio.hpp"
#include "scene/scene.hpp"

namespace rtr {

// Whether any mesh holds a hierarchy (a chunk to write).
bool hasClusterLods(const Scene& scene);
// The chunk's body (16-byte aligned from its start).
void writeClusterLods(ByteWriter& w, const Scene& scene);
// Reads a body of `size` bytes at r.pos() (the meshes, their clusters and vertex counts already read)
// into the meshes' `lod`, checking everything the renderer trusts; a fault names its byte offset.
void readClusterLods(ByteReader& r, uint64_t size, Scene& scene);

}  // namespace rtr
