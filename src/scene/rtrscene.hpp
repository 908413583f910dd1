#pragma once
// Our baked format (.rtrscene): versioned, scalar factors instead of fallback textures, 16-bit indices where
// a mesh allows, 16-byte aligned arrays, a checksum over the payload. Byte table: docs/rtrscene-format.md.
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>

#include "core/atomic_file.hpp"
#include "scene/scene.hpp"

namespace rtr {

// 2 added lights, 3 clusters, 4 a checksum summed on all cores (pieceChecksum64), 5 what glTF brings
// (instances, samplers, uv transforms, more attributes and light kinds), 6 chunks after the version-5
// layout (TEXS: textures baked as the GPU samples them; CLOD: the cluster hierarchies); versions 1-5 still
// load (older writers drop the chunks).
constexpr uint32_t kRtrSceneVersion = 6;

// `version` below the current one writes an older layout (lights need 2, clusters 3, the checksum of
// version 4), for tests of the reader; a scene holding what only version 5 stores is refused in older
// ones. Textures held in memory (Texture::bytes) are refused: the file names image files, or holds baked
// texels (Texture::baked: all of a scene's textures or none; version 6).
std::string encodeRtrScene(const Scene& scene, uint32_t version = kRtrSceneVersion);
// The same bytes (the current version) streamed into `file` as they are made, in windows of `window`
// bytes (a multiple of 1 MiB) summed on `threads` threads and written while the next fills: the file is
// never whole in memory. Returns its size; the caller syncs and commits `file`. Throws rtr::Error naming
// the file on a write error (the temporary is then the caller's to drop).
// `ready`, when given, lets the write run beside the build of the meshes' clusters (rtr-bake: the clusters
// reorder each mesh's indices, and everything before them in the file is final already): before the
// writer reads the indices of mesh m up to triangle t it calls ready(m, t) (t = all of them: its clusters
// too), and before the chunks ready(mesh count, 0). It returns once those are final, or throws to stop.
using WriteGate = std::function<void(size_t mesh, size_t triangles)>;
uint64_t writeRtrScene(const Scene& scene, AtomicFile& file, unsigned threads = 0, size_t window = size_t(64) << 20,
                       const WriteGate& ready = {});
// Validates everything (sizes, counts, strings, indices, texture ids, finite values, clusters, checksum).
// The checksum (version 4), the arrays and their checks run on `threads` threads (0: one per core, or
// one for a file under 4 MiB); the scene and any fault reported do not depend on the count. Baked texels
// are checked for layout here and unpacked by their user (scene/baked_texels.hpp); they point into `bytes`
// kept alive by `owner`, or without one into a copy of the TEXS chunk.
Scene decodeRtrScene(std::span<const uint8_t> bytes, const std::string& file, unsigned threads = 0,
                     const std::shared_ptr<const void>& owner = {});
Scene loadRtrScene(const std::filesystem::path& file);

}  // namespace rtr
