#pragma once
// Polygon triangulation for the OBJ reader: convex polygons give the fan (0,1,2),(0,2,3),... (what the
// course's tools produce, so baked bytes stay the same); others are ear-clipped in the plane of their
// Newell normal, as other OBJ loaders do.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

namespace rtr {

// Appends triangles as corner indices into `polygon` to `out`, in the polygon's winding. Returns false
// when ear clipping found no ear (a self-intersecting polygon): the rest was fan-triangulated then.
// Zero-area pieces (collinear or repeated corners) produce no triangle.
bool triangulatePolygon(std::span<const glm::vec3> polygon, std::vector<std::array<uint32_t, 3>>& out);

}  // namespace rtr
