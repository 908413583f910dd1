#pragma once
// Writes OBJ text, zstd-compressed in frames of about 4 MiB of text when the name ends in .zst, with a few
// primitives.
#include <cstdio>
#include <filesystem>
#include <string>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <zstd.h>

namespace scenegen {

class ObjWriter {
 public:
  ObjWriter(const std::filesystem::path& file, int zstdLevel);
  ~ObjWriter();
  void line(const std::string& s);
  void object(const std::string& name, const std::string& material);

  // Each returns after writing v/vt/vn records and faces; indices are absolute unless `relative`.
  void grid(glm::vec3 origin, glm::vec3 du, glm::vec3 dv, int nu, int nv, glm::vec2 uvScale);
  void box(glm::vec3 min, glm::vec3 max, float uvScale);
  // Side wall with smooth normals, caps as single n-gons (fan-triangulated by the loader).
  void cylinder(glm::vec3 base, float radius, float height, int segments, int rings);
  // Lumpy sphere without normals (the loader generates them) but with spherical texcoords.
  void blob(glm::vec3 centre, glm::vec3 radii, int stacks, int slices, float lumpiness);
  // Disc written with negative (relative) indices: one polygon with `segments` corners.
  void disc(glm::vec3 centre, glm::vec3 normal, float radius, int segments);
  // Two crossed quads (foliage cards) with relative indices.
  void cards(glm::vec3 base, float width, float height, float turnRad);
  size_t vertices() const { return v_; }
  void finish();

 private:
  static constexpr size_t kFrameBytes = size_t(4) << 20;  // text per zstd frame
  void flush();
  std::FILE* f_ = nullptr;
  ZSTD_CCtx* z_ = nullptr;
  std::string buf_;
  size_t v_ = 0, vt_ = 0, vn_ = 0;
  char tmp_[256];
};

}  // namespace scenegen
