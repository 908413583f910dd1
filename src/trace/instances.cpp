#include "trace/instances.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "core/error.hpp"

namespace rtr::trace {

namespace {

// A scene-space ray against a box, conservatively: the slab distances are widened by a few ulps so a box
// the ray meets is never culled (a false positive only costs a visit). Axes the ray runs parallel to are
// tested on the origin; a NaN slab distance (0 × ∞) is ignored by the min/max order.
bool boxHit(const glm::vec3& lo, const glm::vec3& hi, const Ray& r, const glm::vec3& inv, float tMax, float& tEntry) {
  float t0 = 0.0f, t1 = tMax;
  for (int a = 0; a < 3; ++a) {
    if (r.direction[a] == 0.0f) {
      if (!(r.origin[a] >= lo[a] && r.origin[a] <= hi[a])) return false;
      continue;
    }
    float ta = (lo[a] - r.origin[a]) * inv[a], tb = (hi[a] - r.origin[a]) * inv[a];
    if (ta > tb) std::swap(ta, tb);
    ta -= std::abs(ta) * 1e-6f;
    tb += std::abs(tb) * 1e-6f;
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  tEntry = t0;
  return t0 <= t1;
}

}  // namespace

InstanceBvh::InstanceBvh(std::span<const Triangle> tris, std::span<const uint8_t> castsShadow, std::span<const Object> objects,
                         std::span<const Placement> placements, unsigned threads) {
  std::vector<glm::dvec3> objLo, objHi;
  for (const Object& o : objects) {
    if (size_t(o.first) + o.count > tris.size()) throw Error("instance BVH: an object's triangles are out of range");
    const std::span<const Triangle> part = tris.subspan(o.first, o.count);
    // Small meshes build on one thread (the tree is the same with any count; threads cost a start each).
    bvhs_.emplace_back(part, castsShadow.empty() ? castsShadow : castsShadow.subspan(o.first, o.count),
                       o.count >= 65536 ? threads : 1u);
    objectFirst_.push_back(o.first);
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    for (const Triangle& t : part)
      for (const glm::vec3& v : {t.v0, t.v1, t.v2})
        if (std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)) {
          lo = glm::min(lo, glm::dvec3(v));
          hi = glm::max(hi, glm::dvec3(v));
        }
    objLo.push_back(lo);
    objHi.push_back(hi);
  }
  // Scene-space boxes: the object box's eight corners transformed in double, padded by 1e-5 of the terms'
  // magnitude (far more than the float transform of a vertex can be off by).
  std::vector<glm::vec3> lo, hi;
  std::vector<uint32_t> ids;
  for (uint32_t i = 0; i < placements.size(); ++i) {
    const Placement& p = placements[i];
    if (p.object >= objects.size())
      throw Error("instance " + std::to_string(i) + " names object " + std::to_string(p.object) + " of " +
                  std::to_string(objects.size()));
    const glm::dmat4 m(p.toScene);
    const glm::dmat3 m3(m);
    if (glm::determinant(m3) == 0.0 || !std::isfinite(glm::determinant(m3)))
      throw Error("instance " + std::to_string(i) + ": its transform is singular or not finite");
    inst_.push_back({p.object, p.toScene, glm::mat4(glm::inverse(m)), glm::mat3(glm::transpose(glm::inverse(m3))),
                     glm::determinant(m3) < 0.0});
    lo.push_back(glm::vec3(INFINITY));
    hi.push_back(glm::vec3(-INFINITY));
    const glm::dvec3 a = objLo[p.object], b = objHi[p.object];
    if (!(a.x <= b.x)) continue;  // no finite triangle: never hit
    const glm::dmat3 am(glm::abs(m3[0]), glm::abs(m3[1]), glm::abs(m3[2]));
    glm::dvec3 l(INFINITY), h(-INFINITY), mag(0.0);
    for (int c = 0; c < 8; ++c) {
      const glm::dvec3 corner(c & 1 ? b.x : a.x, c & 2 ? b.y : a.y, c & 4 ? b.z : a.z);
      const glm::dvec3 q = glm::dvec3(m * glm::dvec4(corner, 1.0));
      l = glm::min(l, q);
      h = glm::max(h, q);
      mag = glm::max(mag, am * glm::abs(corner) + glm::abs(glm::dvec3(m[3])));
    }
    lo.back() = glm::vec3(l - 1e-5 * mag - 1e-30);
    hi.back() = glm::vec3(h + 1e-5 * mag + 1e-30);
    ids.push_back(i);
  }
  if (ids.empty()) return;
  nodes_.reserve(2 * ids.size());
  nodes_.push_back({});
  build(ids, 0, uint32_t(ids.size()), lo, hi);
  order_ = std::move(ids);
}

// Node 0 is filled for the whole range; children are made in pairs. Median split of the centroids along
// their widest axis, leaves of at most two instances: the top level is small and rarely the cost.
void InstanceBvh::build(std::vector<uint32_t>& ids, uint32_t begin, uint32_t end, const std::vector<glm::vec3>& lo,
                        const std::vector<glm::vec3>& hi) {
  // An explicit stack: (node, begin, end).
  struct Task {
    uint32_t node, begin, end;
  };
  std::vector<Task> tasks{{0, begin, end}};
  while (!tasks.empty()) {
    const Task t = tasks.back();
    tasks.pop_back();
    glm::vec3 l(INFINITY), h(-INFINITY), cl(INFINITY), ch(-INFINITY);
    for (uint32_t i = t.begin; i < t.end; ++i) {
      l = glm::min(l, lo[ids[i]]);
      h = glm::max(h, hi[ids[i]]);
      const glm::vec3 c = 0.5f * (lo[ids[i]] + hi[ids[i]]);
      cl = glm::min(cl, c);
      ch = glm::max(ch, c);
    }
    nodes_[t.node].lo = l;
    nodes_[t.node].hi = h;
    if (t.end - t.begin <= 2) {
      nodes_[t.node].first = t.begin;
      nodes_[t.node].count = t.end - t.begin;
      continue;
    }
    const glm::vec3 e = ch - cl;
    const int axis = e.x >= e.y && e.x >= e.z ? 0 : e.y >= e.z ? 1 : 2;
    const uint32_t mid = t.begin + (t.end - t.begin) / 2;
    std::nth_element(ids.begin() + t.begin, ids.begin() + mid, ids.begin() + t.end, [&](uint32_t a, uint32_t b) {
      const float ca = lo[a][axis] + hi[a][axis], cb = lo[b][axis] + hi[b][axis];
      return ca < cb || (ca == cb && a < b);
    });
    const uint32_t child = uint32_t(nodes_.size());
    nodes_.push_back({});
    nodes_.push_back({});
    nodes_[t.node].first = child;
    nodes_[t.node].count = 0;
    tasks.push_back({child, t.begin, mid});
    tasks.push_back({child + 1, mid, t.end});
  }
}

template <bool kAny>
bool InstanceBvh::walk(const Ray& ray, IntersectMethod method, Hit& best) const {
  if (nodes_.empty()) return false;
  const glm::vec3 inv(1.0f / ray.direction.x, 1.0f / ray.direction.y, 1.0f / ray.direction.z);
  struct Entry {
    uint32_t node;
    float t;
  };
  Entry stack[128];
  int sp = 0;
  float t0;
  if (!boxHit(nodes_[0].lo, nodes_[0].hi, ray, inv, best.t, t0)) return false;
  stack[sp++] = {0, t0};
  while (sp > 0) {
    const Entry e = stack[--sp];
    if (e.t > best.t) continue;  // beyond the closest hit so far
    const Node& n = nodes_[e.node];
    if (n.count > 0) {
      for (uint32_t i = n.first; i < n.first + n.count; ++i) {
        const uint32_t id = order_[i];
        const Inst& in = inst_[id];
        const Ray r{glm::vec3(in.toObject * glm::vec4(ray.origin, 1.0f)), glm::mat3(in.toObject) * ray.direction, best.t};
        if constexpr (kAny) {
          if (bvhs_[in.object].occluded(r, method)) return true;
        } else {
          const Hit h = bvhs_[in.object].closest(r, method);
          if (h.hit() && h.t < best.t) {
            best = h;
            best.prim += objectFirst_[in.object];
            best.instance = id;
          }
        }
      }
      continue;
    }
    float ta = 0.0f, tb = 0.0f;
    const bool ha = boxHit(nodes_[n.first].lo, nodes_[n.first].hi, ray, inv, best.t, ta);
    const bool hb = boxHit(nodes_[n.first + 1].lo, nodes_[n.first + 1].hi, ray, inv, best.t, tb);
    // Nearer child on top; any-hit queries take the farther first, as the mesh BVH's do (docs/tracer.md).
    const bool aFirst = kAny ? ta >= tb : ta <= tb;
    if (ha && hb) {
      stack[sp++] = aFirst ? Entry{n.first + 1, tb} : Entry{n.first, ta};
      stack[sp++] = aFirst ? Entry{n.first, ta} : Entry{n.first + 1, tb};
    } else if (ha) {
      stack[sp++] = {n.first, ta};
    } else if (hb) {
      stack[sp++] = {n.first + 1, tb};
    }
  }
  return false;
}

Hit InstanceBvh::closest(const Ray& ray, IntersectMethod method) const {
  Hit best;
  best.t = ray.tMax;
  walk<false>(ray, method, best);
  return best.hit() ? best : Hit{};
}

bool InstanceBvh::occluded(const Ray& ray, IntersectMethod method) const {
  Hit unused;
  unused.t = ray.tMax;
  return walk<true>(ray, method, unused);
}

}  // namespace rtr::trace
