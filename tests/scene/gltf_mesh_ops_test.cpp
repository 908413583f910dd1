// Mesh operations of the glTF path: MikkTSpace-style tangents (split at mirrored uv seams) and
// flattening instances for renderers that do not draw them.
#include <cmath>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "scene/mesh_ops.hpp"

using namespace rtr;

namespace {

// A quad in the z = 0 plane, two triangles sharing the edge x = 0; the right half's uvs mirror the
// left half's (u runs away from the seam on both sides), as a mirrored normal map is laid out.
Mesh mirroredQuad() {
  Mesh m;
  m.positions = {{0, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {1, 0, 0}};
  m.normals.assign(4, glm::vec3(0, 0, 1));
  m.texcoords = {{0, 0}, {0, 1}, {1, 0}, {1, 0}};
  m.indices = {0, 1, 2, 0, 3, 1};  // both counter-clockwise seen from +z
  return m;
}

TEST(Tangents, FollowUAndSplitAtAMirroredSeam) {
  Mesh m = mirroredQuad();
  generateTangents(m, m.texcoords);
  ASSERT_EQ(m.tangents.size(), m.positions.size());
  // The seam's two vertices are shared by both halves, whose handedness differs: each gets a copy.
  EXPECT_EQ(m.positions.size(), 6u);
  for (size_t t = 0; t < 2; ++t) {
    for (int c = 0; c < 3; ++c) {
      const uint32_t v = m.indices[t * 3 + c];
      const glm::vec4 tan = m.tangents[v];
      // Left half: u grows towards -x; right half: towards +x.
      EXPECT_NEAR(tan.x, t == 0 ? -1.0f : 1.0f, 1e-5) << "triangle " << t << " corner " << c;
      EXPECT_NEAR(glm::dot(glm::vec3(tan), m.normals[v]), 0.0f, 1e-6);
      // The bitangent cross(n, t) * w points where v grows (+y) on both halves.
      const glm::vec3 bit = glm::cross(m.normals[v], glm::vec3(tan)) * tan.w;
      EXPECT_NEAR(bit.y, 1.0f, 1e-5);
    }
  }
  EXPECT_NE(m.indices[0], m.indices[3]);  // the seam vertex 0 is no longer shared
}

TEST(Tangents, NoSplitWithoutAMirror) {
  Mesh m = mirroredQuad();
  m.texcoords = {{0.5f, 0}, {0.5f, 1}, {0, 0}, {1, 0}};  // one continuous uv layout
  generateTangents(m, m.texcoords);
  EXPECT_EQ(m.positions.size(), 4u);
  for (const glm::vec4& t : m.tangents) {
    EXPECT_NEAR(t.x, 1.0f, 1e-5);
    EXPECT_EQ(t.w, 1.0f);
  }
}

TEST(FlattenInstances, TransformsPositionsNormalsAndFlipsMirroredWinding) {
  Scene s;
  s.materials.resize(1);
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.normals.assign(3, glm::vec3(0, 0, 1));
  m.indices = {0, 1, 2};
  for (auto& p : m.positions) m.bounds.extend(p);
  s.meshes.push_back(m);
  s.meshes.push_back(m);  // not placed: dropped
  // A non-uniform scale (normals need the inverse transpose) and a mirror in x.
  const glm::mat4 shear = glm::translate(glm::mat4(1), glm::vec3(0, 0, 5)) *
                          glm::rotate(glm::mat4(1), float(M_PI / 2), glm::vec3(1, 0, 0)) *
                          glm::scale(glm::mat4(1), glm::vec3(1, 3, 1));
  const glm::mat4 mirror = glm::scale(glm::mat4(1), glm::vec3(-1, 1, 1));
  s.instances = {{0, shear}, {0, mirror}};
  const Scene f = flattenInstances(s);
  EXPECT_TRUE(f.instances.empty());
  ASSERT_EQ(f.meshes.size(), 2u);
  // Rotated 90° about x: y -> z, scaled 3 in y first; the normal +z goes to -y.
  EXPECT_NEAR(f.meshes[0].positions[2].z, 8.0f, 1e-5);
  EXPECT_NEAR(f.meshes[0].normals[0].y, -1.0f, 1e-5);
  EXPECT_NEAR(f.meshes[0].bounds.max.z, 8.0f, 1e-5);
  EXPECT_EQ(f.meshes[0].indices, (std::vector<uint32_t>{0, 1, 2}));
  // Mirrored: the winding flips so the face seen from +z stays front-facing with its normal +z.
  EXPECT_EQ(f.meshes[1].positions[1], glm::vec3(-1, 0, 0));
  EXPECT_EQ(f.meshes[1].indices, (std::vector<uint32_t>{0, 2, 1}));
  const glm::vec3 a = f.meshes[1].positions[0], b = f.meshes[1].positions[2], c = f.meshes[1].positions[1];
  EXPECT_GT(glm::dot(glm::cross(b - a, c - a), f.meshes[1].normals[0]), 0.0f);
  EXPECT_FALSE(f.meshes[1].clusters.empty());
}

}  // namespace
