#include "trace/tracer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "core/error.hpp"
#include "trace/shade.hpp"
#include "trace/spawn.hpp"

namespace rtr::trace {

glm::mat4 modelview(const CameraPose& pose, const glm::mat4& model) { return viewMatrix(pose) * model; }

Tracer::Tracer(const Scene& scene, unsigned buildThreads) : scene_(scene) {
  for (uint32_t mi = 0; mi < scene.meshes.size(); ++mi) {
    const Mesh& m = scene.meshes[mi];
    const bool light = m.material < scene.materials.size() && isLightMaterial(scene.materials[m.material]);
    for (uint32_t t = 0; t < m.triangleCount(); ++t) {
      const uint32_t* idx = &m.indices[size_t(t) * 3];
      if (idx[0] >= m.positions.size() || idx[1] >= m.positions.size() || idx[2] >= m.positions.size())
        throw Error("mesh '" + m.name + "': triangle " + std::to_string(t) + " has a vertex index out of range");
      tris_.push_back({m.positions[idx[0]], m.positions[idx[1]], m.positions[idx[2]]});
      triMesh_.push_back(mi);
      triLocal_.push_back(t);
      castsShadow_.push_back(light ? 0 : 1);  // shadow rays pass through the lights' own geometry
    }
  }
  lights_ = extractLights(scene);
  useBvh_ = tris_.size() >= kBruteForceMax;
  if (useBvh_) bvh_ = Bvh(tris_, castsShadow_, buildThreads);
}

Hit Tracer::closestTriangle(const Ray& r, IntersectMethod m) const {
  if (useBvh_) return bvh_.closest(r, m);
  // The brief's loop: every triangle, keep the smallest positive t.
  Hit best;
  Ray q = r;
  for (uint32_t i = 0; i < tris_.size(); ++i) {
    float b1, b2;
    const float t = intersect(m, q, tris_[i], b1, b2);
    if (t > 0.0f) { best = {t, b1, b2, i}; q.tMax = t; }
  }
  return best;
}

bool Tracer::occluded(const Ray& r, IntersectMethod m) const {
  if (useBvh_) return bvh_.occluded(r, m);
  for (uint32_t i = 0; i < tris_.size(); ++i) {
    float b1, b2;
    if (castsShadow_[i] && intersect(m, r, tris_[i], b1, b2) > 0.0f) return true;
  }
  return false;
}

SurfacePoint Tracer::surface(const Ray& r, const Hit& h) const {
  SurfacePoint sp;
  const Triangle& tri = tris_[h.prim];
  const float b0 = 1.0f - h.b1 - h.b2;
  sp.position = b0 * tri.v0 + h.b1 * tri.v1 + h.b2 * tri.v2;
  glm::vec3 ng = glm::cross(tri.v1 - tri.v0, tri.v2 - tri.v0);
  const float len = glm::length(ng);
  ng = len > 0.0f ? ng / len : -glm::normalize(r.direction);
  const Mesh& m = scene_.meshes[triMesh_[h.prim]];
  const uint32_t* idx = &m.indices[size_t(triLocal_[h.prim]) * 3];
  glm::vec3 ns = ng;
  if (m.normals.size() == m.positions.size()) {
    const glm::vec3 n = b0 * m.normals[idx[0]] + h.b1 * m.normals[idx[1]] + h.b2 * m.normals[idx[2]];
    const float nl = glm::length(n);
    if (nl > 0.0f && std::isfinite(nl)) ns = n / nl;
  }
  if (m.texcoords.size() == m.positions.size())
    sp.uv = b0 * m.texcoords[idx[0]] + h.b1 * m.texcoords[idx[1]] + h.b2 * m.texcoords[idx[2]];
  // Two-sided: face the normals towards where the ray came from.
  if (glm::dot(ng, r.direction) > 0.0f) ng = -ng;
  if (glm::dot(ns, ng) < 0.0f) ns = -ns;
  sp.geomNormal = ng;
  sp.normal = ns;
  static const Material kDefault{};
  sp.material = m.material < scene_.materials.size() ? &scene_.materials[m.material] : &kDefault;
  sp.mesh = triMesh_[h.prim];
  return sp;
}

glm::vec3 Tracer::local(const Ray& r, const SurfacePoint& sp, const Frame& f, Counters& c) const {
  const TraceSettings& s = *f.s;
  const Material& mat = *sp.material;
  const glm::vec3 v = -glm::normalize(r.direction);
  if (s.shading == Shading::Pbr) {
    const glm::vec3 toLight = f.pbrLightPos - sp.position;
    const glm::vec3 l = glm::normalize(toLight);
    glm::vec3 lightColor = s.pbrLight.color;
    if (s.shadows && glm::dot(sp.geomNormal, l) > 0.0f) {
      ++c.shadow;
      if (occluded(spawnRay(sp.position, sp.geomNormal, toLight, 1.0f), s.intersect)) lightColor = glm::vec3(0.0f);
    }
    return shadePbr(sp.normal, v, l, lightColor, glm::vec3(s.pbrLight.ambient), mat.baseColor, mat.roughness,
                    mat.metalness, mat.emissive);
  }
  // A light's own surface shows its emission only (it does not light itself).
  if (isLightMaterial(mat)) return mat.ke;
  // Blinn-Phong over every light; in shadow a light gives only its ambient.
  glm::vec3 color = mat.ke;
  const int n = std::max(1, s.areaLightSamples);
  for (const Light& light : lights_) {
    color += blinnPhongAmbient(mat, light.color);
    const int samples = light.area ? n : 1;
    glm::vec3 direct(0.0f);
    for (int i = 0; i < samples; ++i) {
      const glm::vec3 target = light.samplePoint(i, samples);
      const glm::vec3 toLight = target - sp.position;
      const float dist = glm::length(toLight);
      if (!(dist > 0.0f)) continue;
      const glm::vec3 l = toLight / dist;
      const glm::vec3 d = blinnPhongDirect(mat, sp.normal, v, l, light.color);
      if (d == glm::vec3(0.0f)) continue;
      if (s.shadows) {
        if (glm::dot(sp.geomNormal, l) <= 0.0f) continue;  // light behind the surface itself
        ++c.shadow;
        if (occluded(spawnRay(sp.position, sp.geomNormal, toLight, 1.0f), s.intersect)) continue;
      }
      direct += d;
    }
    color += direct / float(samples);
  }
  return color;
}

glm::vec3 Tracer::shade(const Ray& r, int bounces, const Frame& f, Counters& c) const {
  const TraceSettings& s = *f.s;
  const Hit h = closestTriangle(r, s.intersect);
  if (s.shading == Shading::Depth) {
    if (!h.hit()) return glm::vec3(1.0f);
    const float depth = h.t * glm::dot(r.direction, f.depthAxis) / f.depthFar;
    return glm::vec3(std::clamp(depth, 0.0f, 1.0f));
  }
  if (!h.hit()) return s.background;
  const SurfacePoint sp = surface(r, h);
  if (s.shading == Shading::Normals) return glm::abs(sp.normal);  // the brief's "interpolation" view
  const glm::vec3 col = local(r, sp, f, c);
  const float m = std::clamp(sp.material->mirror, 0.0f, 1.0f);
  if (m <= 0.0f || bounces <= 0) return col;  // out of bounces: the surface's own colour
  // Task 7: reflect about the shading normal (the geometric one if that would dive under the surface).
  glm::vec3 n = sp.normal;
  glm::vec3 d = r.direction - 2.0f * glm::dot(r.direction, n) * n;
  if (glm::dot(d, sp.geomNormal) <= 0.0f) n = sp.geomNormal;
  ++c.reflection;
  const glm::vec3 reflected = shade(reflectRay(r, n, sp.position, sp.geomNormal), bounces - 1, f, c);
  return (1.0f - m) * col + m * reflected;  // convex mix: no energy lost or added
}

Tracer::Frame Tracer::makeFrame(const TraceSettings& s) const {
  Frame f;
  f.s = &s;
  f.toScene = glm::inverse(s.model);
  f.pbrLightPos = glm::vec3(f.toScene * glm::vec4(s.pbrLight.position, 1.0f));
  const CameraPose pose = resolvePose(s);
  const glm::vec3 fwd = basis(pose).forward;
  f.depthAxis = glm::transpose(glm::mat3(s.model)) * fwd;
  f.depthFar = resolveLens(s).zFar;
  return f;
}

glm::vec3 Tracer::traceAndShade(const Ray& r, int bounces, const TraceSettings& s) const {
  Counters c;
  return shade(r, bounces, makeFrame(s), c);
}

namespace {
Bounds transformed(const Bounds& b, const glm::mat4& m) {
  if (b.empty()) return b;
  Bounds out;
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 p{i & 1 ? b.max.x : b.min.x, i & 2 ? b.max.y : b.min.y, i & 4 ? b.max.z : b.min.z};
    out.extend(glm::vec3(m * glm::vec4(p, 1.0f)));
  }
  return out;
}
}  // namespace

CameraPose Tracer::resolvePose(const TraceSettings& s) const {
  if (s.pose) return *s.pose;
  const float aspect = float(std::max(1u, s.width)) / float(std::max(1u, s.height));
  return frameBounds(transformed(scene_.bounds(), s.model), s.lens, aspect);
}

Lens Tracer::resolveLens(const TraceSettings& s) const {
  return fitDepthRange(s.lens, transformed(scene_.bounds(), s.model), resolvePose(s));
}

Ray Tracer::calculateRay(const TraceSettings& s, uint32_t px, uint32_t py) const {
  const CameraPose pose = resolvePose(s);
  const float aspect = float(s.width) / float(s.height);
  const CameraRay cr = cameraRay(pose, s.lens, aspect, pixelToNdc(float(px) + 0.5f, float(py) + 0.5f, s.width, s.height));
  const glm::mat4 toScene = glm::inverse(s.model);
  return {glm::vec3(toScene * glm::vec4(cr.origin, 1.0f)), glm::vec3(toScene * glm::vec4(cr.direction, 0.0f))};
}

RenderStats Tracer::render(const TraceSettings& s, ImageF& out, const TileCallback& onTile,
                           std::atomic<bool>* cancel) const {
  if (s.width == 0 || s.height == 0 || s.width > 32768 || s.height > 32768)
    throw Error("image size " + std::to_string(s.width) + "x" + std::to_string(s.height) + " is out of range");
  if (s.bounces < 0 || s.bounces > 64) throw Error("bounces must be in 0..64, got " + std::to_string(s.bounces));
  if (s.shading == Shading::Pbr && !pbrAvailable()) shadePbr({}, {}, {}, {}, {}, {}, 0, 0, {});  // throws
  const auto start = std::chrono::steady_clock::now();
  out.width = s.width;
  out.height = s.height;
  out.pixels.assign(size_t(s.width) * s.height, glm::vec4(s.background, 1.0f));

  const Frame frame = makeFrame(s);
  const CameraPose pose = resolvePose(s);
  const float aspect = float(s.width) / float(s.height);
  const uint32_t ts = std::max(4u, s.tileSize);
  const uint32_t tilesX = (s.width + ts - 1) / ts, tilesY = (s.height + ts - 1) / ts;
  RenderStats stats;
  stats.tilesTotal = tilesX * tilesY;
  std::atomic<uint32_t> next{0};
  std::mutex mutex;  // guards stats and the callback
  const bool debugView = s.shading == Shading::Normals || s.shading == Shading::Depth;

  auto worker = [&] {
    // Denormals only slow us down; flush them (this thread is ours, nothing to restore).
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    Counters c;
    uint64_t primary = 0;
    for (;;) {
      if (cancel && cancel->load(std::memory_order_relaxed)) break;
      const uint32_t tile = next.fetch_add(1);
      if (tile >= stats.tilesTotal) break;
      const TileRect rect{(tile % tilesX) * ts, (tile / tilesX) * ts, std::min(s.width, (tile % tilesX + 1) * ts),
                          std::min(s.height, (tile / tilesX + 1) * ts)};
      for (uint32_t y = rect.y0; y < rect.y1; ++y)
        for (uint32_t x = rect.x0; x < rect.x1; ++x) {
          const CameraRay cr =
              cameraRay(pose, s.lens, aspect, pixelToNdc(float(x) + 0.5f, float(y) + 0.5f, s.width, s.height));
          const Ray r{glm::vec3(frame.toScene * glm::vec4(cr.origin, 1.0f)),
                      glm::vec3(frame.toScene * glm::vec4(cr.direction, 0.0f))};
          glm::vec3 col = shade(r, s.bounces, frame, c);
          // Debug views hold their value as displayed: encode so that sRGB output shows it unchanged.
          if (debugView) col = {srgbToLinear(col.x), srgbToLinear(col.y), srgbToLinear(col.z)};
          out.at(x, y) = glm::vec4(col, 1.0f);
          ++primary;
        }
      std::lock_guard lock(mutex);
      ++stats.tilesDone;
      if (onTile) onTile(rect);
    }
    std::lock_guard lock(mutex);
    stats.primaryRays += primary;
    stats.shadowRays += c.shadow;
    stats.reflectionRays += c.reflection;
  };
  unsigned n = s.threads ? s.threads : std::max(1u, std::thread::hardware_concurrency());
  n = std::min(n, stats.tilesTotal);
  std::vector<std::thread> pool;
  for (unsigned i = 0; i < n; ++i) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  stats.cancelled = stats.tilesDone < stats.tilesTotal;
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace rtr::trace
