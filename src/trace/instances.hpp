#pragma once
// A two-level BVH for scenes with instances (Scene::instances): one Bvh per distinct mesh, built once in
// the mesh's object space however often it is placed, and a binary BVH over the instances' scene-space
// boxes. A ray is taken into an instance's object space (t is unchanged by an affine map, so hits of
// different instances compare directly). Queries are single rays; docs/tracer.md says why.
#include <cstdint>
#include <span>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>

#include "trace/bvh.hpp"

namespace rtr::trace {

class InstanceBvh {
 public:
  // A distinct mesh: its triangles [first, first + count) of the tracer's triangle array.
  struct Object {
    uint32_t first = 0, count = 0;
  };
  struct Placement {
    uint32_t object = 0;
    glm::mat4 toScene{1.0f};
  };

  InstanceBvh() = default;
  // tris: every object's triangles in object space; castsShadow: one flag per triangle (empty: all cast).
  InstanceBvh(std::span<const Triangle> tris, std::span<const uint8_t> castsShadow, std::span<const Object> objects,
              std::span<const Placement> placements, unsigned threads = 0);

  // Closest hit in (0, ray.tMax): prim indexes `tris`, instance the placement; t along the scene-space ray.
  Hit closest(const Ray& ray, IntersectMethod method = IntersectMethod::Watertight) const;
  bool occluded(const Ray& ray, IntersectMethod method = IntersectMethod::Watertight) const;

  // Per placement: object to scene, and the normal matrix (inverse transpose of its 3×3 part).
  const glm::mat4& toScene(uint32_t instance) const { return inst_[instance].toScene; }
  const glm::mat3& normalToScene(uint32_t instance) const { return inst_[instance].normal; }
  bool mirrored(uint32_t instance) const { return inst_[instance].mirrored; }  // negative determinant
  size_t objectCount() const { return bvhs_.size(); }

 private:
  struct Inst {
    uint32_t object;
    glm::mat4 toScene, toObject;
    glm::mat3 normal;
    bool mirrored;
  };
  struct Node {
    glm::vec3 lo, hi;
    uint32_t first, count;  // count > 0: a leaf of order_[first, first + count); else children first, first + 1
  };
  void build(std::vector<uint32_t>& ids, uint32_t begin, uint32_t end, const std::vector<glm::vec3>& lo,
             const std::vector<glm::vec3>& hi);
  template <bool kAny>
  bool walk(const Ray& ray, IntersectMethod method, Hit& best) const;

  std::vector<Bvh> bvhs_;
  std::vector<uint32_t> objectFirst_;
  std::vector<Inst> inst_;
  std::vector<Node> nodes_;
  std::vector<uint32_t> order_;
};

}  // namespace rtr::trace
