#include "objwriter.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <glm/geometric.hpp>

namespace scenegen {

ObjWriter::ObjWriter(const std::filesystem::path& file, int zstdLevel) {
  f_ = std::fopen(file.c_str(), "wb");
  if (!f_) throw std::runtime_error("cannot create " + file.string());
  if (file.extension() == ".zst") {
    z_ = ZSTD_createCCtx();
    ZSTD_CCtx_setParameter(z_, ZSTD_c_compressionLevel, zstdLevel);
    ZSTD_CCtx_setParameter(z_, ZSTD_c_nbWorkers, 2);
  }
}

ObjWriter::~ObjWriter() {
  if (z_) ZSTD_freeCCtx(z_);
  if (f_) std::fclose(f_);
}

// Compressed, each flush is a frame of its own that records its size, so a reader can decode frames
// on all cores (src/scene/stream.cpp).
void ObjWriter::flush() {
  if (!z_) {
    if (std::fwrite(buf_.data(), 1, buf_.size(), f_) != buf_.size()) throw std::runtime_error("write failed");
  } else if (!buf_.empty()) {
    std::vector<char> out(ZSTD_compressBound(buf_.size()));
    const size_t n = ZSTD_compress2(z_, out.data(), out.size(), buf_.data(), buf_.size());
    if (ZSTD_isError(n)) throw std::runtime_error(ZSTD_getErrorName(n));
    if (std::fwrite(out.data(), 1, n, f_) != n) throw std::runtime_error("write failed");
  }
  buf_.clear();
}

void ObjWriter::line(const std::string& s) {
  buf_ += s;
  buf_ += '\n';
  if (buf_.size() > (z_ ? kFrameBytes : size_t(1) << 20)) flush();
}

void ObjWriter::finish() {
  flush();
  std::fclose(f_);
  f_ = nullptr;
}

void ObjWriter::object(const std::string& name, const std::string& material) {
  line("o " + name);
  line("usemtl " + material);
}

#define EMIT(...) (std::snprintf(tmp_, sizeof tmp_, __VA_ARGS__), line(tmp_))

void ObjWriter::grid(glm::vec3 o, glm::vec3 du, glm::vec3 dv, int nu, int nv, glm::vec2 uvScale) {
  const glm::vec3 n = glm::normalize(glm::cross(du, dv));
  const size_t v0 = v_, t0 = vt_;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      glm::vec3 p = o + du * (float(i) / nu) + dv * (float(j) / nv);
      EMIT("v %.5f %.5f %.5f", p.x, p.y, p.z);
      EMIT("vt %.5f %.5f", uvScale.x * i / nu, uvScale.y * j / nv);
      ++v_, ++vt_;
    }
  EMIT("vn %.5f %.5f %.5f", n.x, n.y, n.z);
  const size_t ni = ++vn_;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      size_t a = j * (nu + 1) + i + 1, b = a + 1, c = a + nu + 2, d = a + nu + 1;
      EMIT("f %zu/%zu/%zu %zu/%zu/%zu %zu/%zu/%zu %zu/%zu/%zu", v0 + a, t0 + a, ni, v0 + b, t0 + b, ni, v0 + c, t0 + c, ni,
           v0 + d, t0 + d, ni);
    }
}

void ObjWriter::box(glm::vec3 mn, glm::vec3 mx, float s) {
  const glm::vec3 e = mx - mn;
  grid({mn.x, mn.y, mx.z}, {e.x, 0, 0}, {0, e.y, 0}, 1, 1, {e.x * s, e.y * s});   // +z
  grid({mx.x, mn.y, mn.z}, {-e.x, 0, 0}, {0, e.y, 0}, 1, 1, {e.x * s, e.y * s});  // -z
  grid({mx.x, mn.y, mx.z}, {0, 0, -e.z}, {0, e.y, 0}, 1, 1, {e.z * s, e.y * s});  // +x
  grid({mn.x, mn.y, mn.z}, {0, 0, e.z}, {0, e.y, 0}, 1, 1, {e.z * s, e.y * s});   // -x
  grid({mn.x, mx.y, mx.z}, {e.x, 0, 0}, {0, 0, -e.z}, 1, 1, {e.x * s, e.z * s});  // +y
  grid({mn.x, mn.y, mn.z}, {e.x, 0, 0}, {0, 0, e.z}, 1, 1, {e.x * s, e.z * s});   // -y
}

void ObjWriter::cylinder(glm::vec3 base, float r, float h, int seg, int rings) {
  const size_t v0 = v_, t0 = vt_, n0 = vn_;
  for (int j = 0; j <= rings; ++j)
    for (int i = 0; i <= seg; ++i) {
      float a = 6.2831853f * i / seg;
      // a gentle entasis, as classical columns have
      float rr = r * (1.0f - 0.08f * float(j) / rings);
      EMIT("v %.5f %.5f %.5f", base.x + rr * std::cos(a), base.y + h * j / rings, base.z + rr * std::sin(a));
      EMIT("vt %.5f %.5f", 2.0f * i / seg, h * j / rings);
      ++v_, ++vt_;
    }
  for (int i = 0; i <= seg; ++i) {
    float a = 6.2831853f * i / seg;
    EMIT("vn %.5f 0 %.5f", std::cos(a), std::sin(a));
    ++vn_;
  }
  for (int j = 0; j < rings; ++j)
    for (int i = 0; i < seg; ++i) {
      size_t a = j * (seg + 1) + i + 1, b = a + 1, c = a + seg + 2, d = a + seg + 1;
      size_t na = i + 1, nb = i + 2;
      EMIT("f %zu/%zu/%zu %zu/%zu/%zu %zu/%zu/%zu %zu/%zu/%zu", v0 + a, t0 + a, n0 + na, v0 + d, t0 + d, n0 + na, v0 + c, t0 + c,
           n0 + nb, v0 + b, t0 + b, n0 + nb);
    }
  // Caps: one polygon each, sharing the ring's vertices, with their own normals.
  line("vn 0 1 0");
  line("vn 0 -1 0");
  vn_ += 2;
  std::string top = "f", bottom = "f";
  for (int i = 0; i < seg; ++i) {
    size_t t = v0 + rings * (seg + 1) + (seg - i), b = v0 + i + 1;
    top += " " + std::to_string(t) + "/" + std::to_string(t - v0 + t0) + "/" + std::to_string(vn_ - 1);
    bottom += " " + std::to_string(b) + "/" + std::to_string(b - v0 + t0) + "/" + std::to_string(vn_);
  }
  line(top);
  line(bottom);
}

void ObjWriter::blob(glm::vec3 c, glm::vec3 radii, int stacks, int slices, float lump) {
  const size_t v0 = v_, t0 = vt_;
  for (int j = 0; j <= stacks; ++j)
    for (int i = 0; i <= slices; ++i) {
      float th = 3.14159265f * j / stacks, ph = 6.2831853f * (i % slices) / slices;
      glm::vec3 d(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
      float k = 1.0f + lump * std::sin(5.0f * ph + 3.0f * th) * std::sin(4.0f * th);
      glm::vec3 p = c + d * radii * k;
      EMIT("v %.5f %.5f %.5f", p.x, p.y, p.z);
      EMIT("vt %.5f %.5f", float(i) / slices, 1.0f - float(j) / stacks);
      ++v_, ++vt_;
    }
  for (int j = 0; j < stacks; ++j)
    for (int i = 0; i < slices; ++i) {
      size_t a = j * (slices + 1) + i + 1, b = a + 1, cc = a + slices + 2, d = a + slices + 1;
      if (j == 0) EMIT("f %zu/%zu %zu/%zu %zu/%zu", v0 + a, t0 + a, v0 + cc, t0 + cc, v0 + d, t0 + d);
      else if (j == stacks - 1) EMIT("f %zu/%zu %zu/%zu %zu/%zu", v0 + a, t0 + a, v0 + b, t0 + b, v0 + d, t0 + d);
      else EMIT("f %zu/%zu %zu/%zu %zu/%zu %zu/%zu", v0 + a, t0 + a, v0 + b, t0 + b, v0 + cc, t0 + cc, v0 + d, t0 + d);
    }
}

void ObjWriter::disc(glm::vec3 c, glm::vec3 n, float r, int seg) {
  n = glm::normalize(n);
  glm::vec3 u = glm::normalize(glm::cross(std::fabs(n.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0), n));
  glm::vec3 w = glm::cross(n, u);
  for (int i = 0; i < seg; ++i) {
    float a = 6.2831853f * i / seg;
    glm::vec3 p = c + r * (std::cos(a) * u + std::sin(a) * w);
    EMIT("v %.5f %.5f %.5f", p.x, p.y, p.z);
    EMIT("vt %.5f %.5f", 0.5f + 0.5f * std::cos(a), 0.5f + 0.5f * std::sin(a));
    ++v_, ++vt_;
  }
  EMIT("vn %.5f %.5f %.5f", n.x, n.y, n.z);
  ++vn_;
  std::string f = "f";
  for (int i = 0; i < seg; ++i) f += " " + std::to_string(i - seg) + "/" + std::to_string(i - seg) + "/-1";
  line(f);
}

void ObjWriter::cards(glm::vec3 b, float wdt, float h, float turn) {
  for (int k = 0; k < 2; ++k) {
    float a = turn + 1.5707963f * k;
    glm::vec3 d(std::cos(a) * wdt * 0.5f, 0, std::sin(a) * wdt * 0.5f);
    glm::vec3 n(-std::sin(a), 0, std::cos(a));
    EMIT("v %.5f %.5f %.5f", b.x - d.x, b.y, b.z - d.z);
    EMIT("v %.5f %.5f %.5f", b.x + d.x, b.y, b.z + d.z);
    EMIT("v %.5f %.5f %.5f", b.x + d.x, b.y + h, b.z + d.z);
    EMIT("v %.5f %.5f %.5f", b.x - d.x, b.y + h, b.z - d.z);
    line("vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1");
    EMIT("vn %.5f %.5f %.5f", n.x, n.y, n.z);
    v_ += 4, vt_ += 4, ++vn_;
    line("f -4/-4/-1 -3/-3/-1 -2/-2/-1 -1/-1/-1");
  }
}

}  // namespace scenegen
