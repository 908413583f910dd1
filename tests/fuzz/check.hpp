#pragma once
// What every fuzz target checks besides "no crash, no sanitizer report": a loaded scene is safe to use,
// and a refusal names the input (the project's rule for bad input).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <unistd.h>

#include "core/error.hpp"
#include "cluster.h"
#include "scene/scene.hpp"

namespace rtr::fuzz {

// Set in a child process that a target forks (fuzz_spirv): a broken invariant then exits with status 3,
// so the parent tells it from a third-party library's abort.
inline bool exitOnBrokenInvariant = false;

// Aborts (a finding for libFuzzer) when `ok` is false, printing what broke.
inline void require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz invariant broken: %s\n", what);
    if (exitOnBrokenInvariant) _exit(3);
    std::abort();
  }
}

inline void requireNamesFile(const rtr::Error& e, const char* file) {
  require(std::strstr(e.what(), file) != nullptr, "the error message does not name the file");
}

// Everything the renderers and the tracer index without further checks.
inline void checkScene(const Scene& s) {
  for (const Material& m : s.materials)
    for (uint32_t t : m.textures) require(t == kNoTexture || t < s.textures.size(), "texture id out of range");
  for (const Texture& t : s.textures) require(t.channels >= 1 && t.channels <= 4, "texture channel count");
  for (const Mesh& m : s.meshes) {
    require(m.material < s.materials.size(), "material id out of range");
    require(m.normals.size() == m.positions.size(), "normal count differs from position count");
    require(m.texcoords.empty() || m.texcoords.size() == m.positions.size(), "texcoord count differs");
    require(m.indices.size() % 3 == 0, "index count not a multiple of 3");
    for (uint32_t i : m.indices) require(i < m.positions.size(), "vertex index out of range");
    uint32_t next = 0;  // clusters tile the triangles in order, within the GPU's limits
    for (const Cluster& c : m.clusters) {
      require(c.firstTriangle == next && c.triangleCount >= 1 && c.triangleCount <= CLUSTER_MAX_TRIANGLES, "cluster range");
      require(std::isfinite(c.center.x + c.center.y + c.center.z + c.radius + c.coneCutoff) && c.radius >= 0.0f,
              "cluster bounds");
      next += c.triangleCount;
    }
    require(m.clusters.empty() || next == m.triangleCount(), "clusters do not cover the triangles");
    for (size_t n : {m.texcoords1.size(), m.tangents.size(), m.colors.size()})
      require(n == 0 || n == m.positions.size(), "attribute count differs from position count");
  }
  for (const Instance& i : s.instances) require(i.mesh < s.meshes.size(), "instance mesh id out of range");
}

}  // namespace rtr::fuzz
