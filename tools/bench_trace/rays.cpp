#include "rays.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <glm/common.hpp>
#include <glm/trigonometric.hpp>

#include "core/camera.hpp"
#include "trace/spawn.hpp"

namespace rtr::trace {
namespace {

// Interleaves the low 16 bits of x and y (x in the even bits): the Z-order of a pixel.
uint32_t zOrder(uint32_t x, uint32_t y) {
  auto spread = [](uint32_t v) {
    v &= 0xFFFFu;
    v = (v | v << 8) & 0x00FF00FFu;
    v = (v | v << 4) & 0x0F0F0F0Fu;
    v = (v | v << 2) & 0x33333333u;
    return (v | v << 1) & 0x55555555u;
  };
  return spread(x) | spread(y) << 1;
}

// Rays regrouped per tile of tile × tile pixels (tiles in row order), within a tile by a direction class
// and then by the pixel's Z-order; packets are then eight consecutive rays. Classes: 0 none, 1 the
// octant (the signs of the direction), 2 the octant and the axis of the largest component.
std::vector<Ray> mirrorTiles(const std::vector<Ray>& rays, const std::vector<uint32_t>& pixel, int res, int tile, int classes) {
  std::vector<std::pair<uint64_t, uint32_t>> key(rays.size());
  const uint32_t tilesX = uint32_t((res + tile - 1) / tile);
  for (size_t i = 0; i < rays.size(); ++i) {
    const uint32_t x = pixel[i] % uint32_t(res), y = pixel[i] / uint32_t(res);
    const glm::vec3 d = rays[i].direction;
    uint32_t c = 0;
    if (classes >= 1) c = (d.x < 0) | (d.y < 0) << 1 | (d.z < 0) << 2;
    if (classes >= 2) {
      const glm::vec3 a = glm::abs(d);
      c = c * 3 + (a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2);
    }
    const uint64_t t = uint64_t(y / uint32_t(tile)) * tilesX + x / uint32_t(tile);
    key[i] = {t << 40 | uint64_t(c) << 32 | zOrder(x % uint32_t(tile), y % uint32_t(tile)), uint32_t(i)};
  }
  std::sort(key.begin(), key.end());
  std::vector<Ray> out(rays.size());
  for (size_t i = 0; i < rays.size(); ++i) out[i] = rays[key[i].second];
  return out;
}

}  // namespace

Rays makeRays(const std::vector<Triangle>& tris, const Bounds& bounds, bool sphere, const Bvh& bvh, int res,
              const std::vector<int>& tiles) {
  Lens lens;
  CameraPose pose = frameBounds(bounds, lens, 1.0f);
  // The unit sphere just inscribed in the square image (about 78 % of rays hit).
  if (sphere) pose.position = {0.0f, 0.0f, 1.01f / std::sin(glm::radians(lens.fovYDeg * 0.5f))};
  auto cameraRays = [&](const Lens& l) {
    std::vector<Ray> rays(size_t(res) * res);
    for (int y = 0; y < res; ++y)
      for (int x = 0; x < res; ++x) {
        const CameraRay cr = cameraRay(pose, l, 1.0f, pixelToNdc(x + 0.5f, y + 0.5f, res, res));
        rays[size_t(y) * res + x] = {cr.origin, cr.direction};
      }
    return rays;
  };
  Rays r;
  r.primary = cameraRays(lens);
  // Orthographic: every ray runs parallel to two axes (the case that once made our traversal visit every
  // box across the view).
  Lens orthoLens = lens;
  orthoLens.orthographic = true;
  orthoLens.orthoHalfHeight = sphere ? 1.01f : 0.55f * std::max(bounds.extent().x, bounds.extent().y);
  r.ortho = cameraRays(orthoLens);
  const glm::vec3 light = bounds.center() + glm::vec3(0.3f, 1.0f, 0.8f) * glm::length(bounds.extent());
  size_t nHit = 0;
  for (const Ray& ray : r.primary) {
    const Hit h = bvh.closest(ray);
    if (!h.hit()) continue;
    r.hitPixel.push_back(uint32_t(&ray - r.primary.data()));
    ++nHit;
    const Triangle& t = tris[h.prim];
    const glm::vec3 p = (1 - h.b1 - h.b2) * t.v0 + h.b1 * t.v1 + h.b2 * t.v2;
    glm::vec3 ng = glm::normalize(glm::cross(t.v1 - t.v0, t.v2 - t.v0));
    if (glm::dot(ng, ray.direction) > 0) ng = -ng;
    r.shadow.push_back(spawnRay(p, ng, light - p, 1.0f));
    r.mirror.push_back(reflectRay(ray, ng, p, ng));
  }
  for (int t : tiles)
    for (int c = 0; c < 3; ++c)
      r.regrouped.push_back({"mirror, " + std::to_string(t) + "² tiles" +
                                 (c == 0   ? ", Z-order"
                                  : c == 1 ? ", by octant"
                                           : ", by octant and major axis"),
                             mirrorTiles(r.mirror, r.hitPixel, res, t, c)});
  std::printf("%.1f %% of primary rays hit; %zu shadow rays to a point light, %zu mirror rays\n\n",
              100.0 * double(nHit) / double(r.primary.size()), r.shadow.size(), r.mirror.size());
  return r;
}

}  // namespace rtr::trace
