#pragma once
// bench-trace's rays: the sets every comparison traces (primary, orthographic, shadow, mirror) and the
// mirror rays regrouped per pixel tile (--mirror-tiles).
#include <string>
#include <utility>
#include <vector>

#include "core/bounds.hpp"
#include "trace/bvh.hpp"

namespace rtr::trace {

struct RaySet {
  const char* name;
  const std::vector<Ray>* rays;
  bool any;
  PacketKind kind;  // closest hit: what our packets are told the rays are
};

// The rays every comparison uses: primary rays through pixel centres from the default framing pose (the
// viewer's and rtr-trace's), the same view orthographic, and from our hits a shadow ray to a point light
// and a mirror ray each (the same rays go to both tracers).
struct Rays {
  std::vector<Ray> primary, ortho, shadow, mirror;
  std::vector<uint32_t> hitPixel;  // the pixel of each shadow and mirror ray
  // --mirror-tiles: the mirror rays regrouped per tile of pixels (mirrorTiles below)
  std::vector<std::pair<std::string, std::vector<Ray>>> regrouped;
  std::vector<RaySet> sets() const {
    std::vector<RaySet> s{{"primary", &primary, false, PacketKind::Coherent},
                          {"primary, orthographic", &ortho, false, PacketKind::Coherent},
                          {"shadow (any hit)", &shadow, true, PacketKind::Coherent},
                          {"mirror", &mirror, false, PacketKind::Scattered}};
    for (const auto& [name, rays] : regrouped) s.push_back({name.c_str(), &rays, false, PacketKind::Scattered});
    return s;
  }
};

// The rays of one scene at res × res pixels, with the mirror rays regrouped for each tile size in `tiles`.
Rays makeRays(const std::vector<Triangle>& tris, const Bounds& bounds, bool sphere, const Bvh& bvh, int res,
              const std::vector<int>& tiles);

}  // namespace rtr::trace
