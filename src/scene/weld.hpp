#pragma once
// Triangle soup (corners indexing shared attribute arrays) to an indexed mesh: degenerate triangles
// dropped, area-weighted normals generated where a corner has none (split at a crease angle), vertices
// welded within 1e-5.
#include <cstdint>
#include <functional>
#include <span>

#include "scene/scene.hpp"

namespace rtr {

constexpr uint32_t kAbsent = 0xFFFFFFFFu;

struct Corner {
  uint32_t p, t, n;  // 0-based into positions/texcoords/normals; kAbsent where the face gave none
  bool operator==(const Corner&) const = default;
};

constexpr float kWeldTolerance = 1e-5f;

struct WeldCounts {
  size_t degenerate = 0;  // triangles dropped
  size_t triangles = 0;   // triangles kept
  size_t vertices = 0;    // vertices after welding
};

constexpr float kDefaultCreaseDeg = 40.0f;

// `corners` holds 3 per triangle; where a corner has no normal, its n is overwritten (the id of a
// generated normal: the caller's corners are the weld's scratch space, and their pages are given back
// as it goes: their contents are lost). Fills out.positions/normals/texcoords/colors/indices/bounds (not name or
// material). A generated normal averages the faces at its position within `creaseDeg` of its own face (0:
// flat, 180: smooth). `colors`: one per position, or empty. Runs on `threads` (0: all cores) in fixed
// pieces: the mesh is the same for any thread count. `cornersDone`, when given, is called once `corners`
// is read no more, before the mesh is made: its owner may free it there (memory at a large bake's peak).
// `step`, when given, is called with each step's name as it begins (rtr-bake --profile).
WeldCounts weldMesh(std::span<Corner> corners, std::span<const glm::vec3> positions, std::span<const glm::vec3> normals,
                    std::span<const glm::vec2> texcoords, Mesh& out, float creaseDeg = kDefaultCreaseDeg,
                    std::span<const glm::vec4> colors = {}, unsigned threads = 1, const std::function<void()>& cornersDone = {},
                    const std::function<void(const char*)>& step = {});

}  // namespace rtr
