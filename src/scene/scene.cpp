#include "scene/scene.hpp"

namespace rtr {

Bounds Scene::bounds() const {
  Bounds b;
  if (instances.empty()) {
    for (const Mesh& m : meshes) b.extend(m.bounds);
  } else {
    for (const Instance& i : instances)
      if (i.mesh < meshes.size()) b.extend(transformed(meshes[i.mesh].bounds, i.transform));
  }
  return b;
}

}  // namespace rtr
