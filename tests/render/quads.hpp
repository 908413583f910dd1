#pragma once
// Small hand-made surfaces for the render tests: axis-aligned quads and unlit glTF materials, so that a
// test's scene says exactly which surface is in front where.
#include <cstdint>

#include <glm/vec3.hpp>

#include "scene/scene.hpp"

namespace rtr::test {

// A quad facing +z at depth z over [x0, x1] × [y0, y1].
inline Mesh quad(float x0, float x1, float y0, float y1, float z, uint32_t material) {
  Mesh q;
  q.material = material;
  q.positions = {{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}};
  q.normals.assign(4, glm::vec3(0, 0, 1));
  q.indices = {0, 1, 2, 0, 2, 3};
  for (auto& p : q.positions) q.bounds.extend(p);
  return q;
}

// A glTF material shown as its base colour (KHR_materials_unlit), blended or opaque.
inline Material unlit(glm::vec3 color, float opacity, bool blend) {
  Material m;
  m.flags = kMaterialGltf | kMaterialUnlit | (blend ? kMaterialBlend : 0u);
  m.baseColor = color;
  m.opacity = opacity;
  return m;
}

}  // namespace rtr::test
