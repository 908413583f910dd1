#pragma once
// Mesh operations the glTF reader needs and the renderers may use: flat normals, tangent generation and
// flattening instances into plain meshes.
#include <vector>

#include <glm/vec2.hpp>

#include "scene/scene.hpp"

namespace rtr {

// Gives every triangle corner its own vertex (all attributes copied) and the triangle's face normal: the
// flat normals glTF asks for when a primitive has none. Degenerate triangles get (0, 0, 1).
void flatNormals(Mesh& mesh);

// Per-vertex tangents (xyz unit, w ±1: bitangent = cross(normal, tangent) · w) from the normals and the
// uv set `uv`, built the MikkTSpace way: each triangle's uv-derivative tangent, projected into the
// vertex's tangent plane, weighted by the corner's angle; a vertex whose triangles disagree in
// handedness (a mirrored uv seam) is split so each side keeps its own. May append vertices and rewrite
// indices. Needs normals and `uv` of the mesh's vertex count.
void generateTangents(Mesh& mesh, const ViewOrVector<glm::vec2>& uv);

// A scene with every instance made a plain mesh (positions by the transform, normals by its inverse
// transpose, winding flipped where the transform mirrors) and no instances: for a renderer that does
// not draw instances yet. A scene without instances comes back unchanged. Clusters are rebuilt.
Scene flattenInstances(const Scene& scene);

}  // namespace rtr
