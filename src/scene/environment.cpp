#include "scene/environment.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "environment.h"

namespace rtr {

namespace {

constexpr float kPi = 3.14159265358979f;

float luminance(const glm::vec4& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

// sin(theta) of row y's centre, and of a point at v (theta = v pi). Never 0: the pdf divides by it.
float rowSin(uint32_t y, uint32_t h) { return std::max(std::sin((float(y) + 0.5f) / float(h) * kPi), 1e-6f); }

}  // namespace

Environment::Environment(ImageF radiance, float intensity, float rotationRad)
    : map_(std::move(radiance)), rotation_(rotationRad) {
  if (map_.width == 0 || map_.height == 0 || map_.pixels.size() != size_t(map_.width) * map_.height)
    throw Error("environment map is empty");
  if (!std::isfinite(intensity) || intensity < 0.0f) throw Error("environment intensity must be finite and >= 0");
  for (glm::vec4& p : map_.pixels) {
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(p[c]) || p[c] < 0.0f) throw Error("environment map has a negative or non-finite texel");
      p[c] *= intensity;
    }
    p.a = 1.0f;
  }
  buildSampling();
}

Environment Environment::load(const EnvironmentSettings& s) {
  if (s.source == "none" || s.source.empty()) return {};
  const float rotation = s.rotationDeg * kPi / 180.0f;
  if (s.source == "sky") return Environment(makeSky({}), s.intensity, rotation);
  const std::filesystem::path file = s.source;
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext != ".hdr" && ext != ".exr") throw UsageError("--env: '" + s.source + "' is not 'sky', 'none' or an .hdr/.exr file");
  try {
    return Environment(loadLinearImage(file), s.intensity, rotation);
  } catch (const UsageError&) { throw; } catch (const Error& e) {
    const std::string what = e.what();
    if (what.find(file.string()) != std::string::npos) throw;
    throw Error(file.string() + ": " + what);
  }
}

glm::vec3 Environment::lookup(const glm::vec3& d) const {
  if (empty()) return glm::vec3(0.0f);
  const glm::vec2 uv = shader::envDirToUv(d, rotation_);
  const float x = uv.x * float(map_.width) - 0.5f, y = uv.y * float(map_.height) - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float tx = x - fx, ty = y - fy;
  const int w = int(map_.width), h = int(map_.height);
  auto texel = [&](int xi, int yi) {
    xi = ((xi % w) + w) % w;  // around the sphere
    yi = std::clamp(yi, 0, h - 1);
    return glm::vec3(map_.at(uint32_t(xi), uint32_t(yi)));
  };
  const int x0 = int(fx), y0 = int(fy);
  return glm::mix(glm::mix(texel(x0, y0), texel(x0 + 1, y0), tx), glm::mix(texel(x0, y0 + 1), texel(x0 + 1, y0 + 1), tx), ty);
}

void Environment::buildSampling() {
  const uint32_t w = map_.width, h = map_.height;
  const size_t n = size_t(w) * h;
  std::vector<double> weight(n);
  double total = 0.0;
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) total += weight[size_t(y) * w + x] = double(luminance(map_.at(x, y))) * rowSin(y, h);
  if (!(total > 0.0)) {  // black: sample the sphere uniformly
    total = 0.0;
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < w; ++x) total += weight[size_t(y) * w + x] = rowSin(y, h);
  }
  // Vose's alias method: every slot holds its texel with probability prob_ and its alias otherwise.
  density_.resize(n);
  prob_.assign(n, 1.0f);
  alias_.resize(n);
  std::vector<double> scaled(n);
  std::vector<uint32_t> small, large;
  for (size_t i = 0; i < n; ++i) {
    scaled[i] = weight[i] / total * double(n);
    density_[i] = float(scaled[i]);
    alias_[i] = uint32_t(i);
    (scaled[i] < 1.0 ? small : large).push_back(uint32_t(i));
  }
  while (!small.empty() && !large.empty()) {
    const uint32_t s = small.back(), l = large.back();
    small.pop_back();
    prob_[s] = float(scaled[s]);
    alias_[s] = l;
    scaled[l] -= 1.0 - scaled[s];
    if (scaled[l] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }  // what is left in either list keeps its own slot (prob 1): rounding only

  // SH projection, each texel weighted by its solid angle.
  sh_.fill(glm::vec3(0.0f));
  const double dPhi = 2.0 * kPi / w;
  std::array<glm::dvec3, 9> acc{};
  for (uint32_t y = 0; y < h; ++y) {
    const double dOmega = dPhi * (std::cos(double(y) / h * kPi) - std::cos(double(y + 1) / h * kPi));  // exact
    for (uint32_t x = 0; x < w; ++x) {
      const glm::vec3 d = shader::envUvToDir({(x + 0.5f) / w, (y + 0.5f) / h}, rotation_);
      const glm::dvec3 l = glm::dvec3(glm::vec3(map_.at(x, y))) * dOmega;
      for (int i = 0; i < 9; ++i) acc[i] += l * double(shader::envSh(i, d));
    }
  }
  for (int i = 0; i < 9; ++i) sh_[i] = glm::vec3(acc[i]);
}

EnvSample Environment::sample(glm::vec2 u) const {
  if (empty()) return {glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0.0f), 0.0f};
  const size_t n = prob_.size();
  const float scaled = std::min(u.x, 0x1.fffffep-1f) * float(n);
  const size_t slot = std::min(size_t(scaled), n - 1);
  float frac = scaled - float(slot);
  size_t texel = slot;
  // The fraction left over picks keep-or-alias and, stretched back to [0,1), the row offset.
  if (frac < prob_[slot]) {
    frac = prob_[slot] > 0.0f ? frac / prob_[slot] : 0.0f;
  } else {
    texel = alias_[slot];
    frac = prob_[slot] < 1.0f ? (frac - prob_[slot]) / (1.0f - prob_[slot]) : 0.0f;
  }
  const uint32_t w = map_.width, h = map_.height;
  const uint32_t tx = uint32_t(texel % w), ty = uint32_t(texel / w);
  const glm::vec2 uv{(float(tx) + std::min(u.y, 0x1.fffffep-1f)) / float(w),
                     (float(ty) + std::min(frac, 0x1.fffffep-1f)) / float(h)};
  EnvSample s;
  s.direction = shader::envUvToDir(uv, rotation_);
  s.radiance = glm::vec3(map_.at(tx, ty));
  s.pdf = density_[texel] / (2.0f * kPi * kPi * std::max(std::sin(uv.y * kPi), 1e-6f));
  return s;
}

glm::vec3 Environment::texel(const glm::vec3& d) const {
  if (empty()) return glm::vec3(0.0f);
  const glm::vec2 uv = shader::envDirToUv(d, rotation_);
  const uint32_t w = map_.width, h = map_.height;
  return glm::vec3(map_.at(std::min(uint32_t(uv.x * float(w)), w - 1), std::min(uint32_t(uv.y * float(h)), h - 1)));
}

float Environment::pdf(const glm::vec3& d) const {
  if (empty()) return 0.0f;
  const glm::vec2 uv = shader::envDirToUv(d, rotation_);
  const uint32_t w = map_.width, h = map_.height;
  const uint32_t tx = std::min(uint32_t(uv.x * float(w)), w - 1), ty = std::min(uint32_t(uv.y * float(h)), h - 1);
  return density_[size_t(ty) * w + tx] / (2.0f * kPi * kPi * std::max(std::sin(uv.y * kPi), 1e-6f));
}

glm::vec3 Environment::irradianceSh(const glm::vec3& n) const {
  glm::vec3 e(0.0f);
  for (int i = 0; i < 9; ++i) e += shader::envShBand(i) * sh_[i] * shader::envSh(i, n);
  return glm::max(e, glm::vec3(0.0f));  // bands 0-2 ring below zero behind a bright sun
}

}  // namespace rtr
