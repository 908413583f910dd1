#include "trace/tracer.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <mutex>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "core/error.hpp"
#include "core/parallel.hpp"
#include "scene/framing.hpp"
#include "scene/textures.hpp"
#include "brdf.h"  // shaders/shared: BRDF_BECKMANN, BRDF_GGX
#include "trace/shade.hpp"
#include "trace/spawn.hpp"

namespace rtr::trace {

glm::mat4 modelview(const CameraPose& pose, const glm::mat4& model) { return viewMatrix(pose) * model; }

namespace {

// The rest of `seg` beyond its hit h at sp: the same line from just past the surface (spawn.hpp's offset,
// so it cannot find that surface again), up to the same end point.
Ray beyond(const Ray& seg, const Hit& h, const SurfacePoint& sp) {
  return spawnRay(sp.position, sp.geomNormal, seg.direction, seg.tMax - h.t);
}

// A ray cone's width on the surface in texture-coordinate units: stretched by 1/|cos| of the incidence.
float uvWidth(const SurfacePoint& sp, const Ray& r, float coneWidth) {
  return sp.uvScale * coneWidth / std::abs(glm::dot(sp.geomNormal, glm::normalize(r.direction)));
}

// glTF's normal map: the texel's tangent-space normal (2·rgb − 1, xy times `scale`) on the frame of the
// interpolated normal and tangent (bitangent = n × t · w). No texel (x < 0) or no tangent: sp.normal.
glm::vec3 normalMapped(const SurfacePoint& sp, const glm::vec4& texel, float scale) {
  if (texel.x < 0.0f || sp.tangent == glm::vec4(0.0f)) return sp.normal;
  const glm::vec3 n = sp.flipped ? -sp.normal : sp.normal;  // the side the mesh's normals are on
  glm::vec3 t = glm::vec3(sp.tangent) - n * glm::dot(n, glm::vec3(sp.tangent));
  const float tl = glm::length(t);
  if (!(tl > 0.0f)) return sp.normal;
  t /= tl;
  const glm::vec3 b = glm::cross(n, t) * sp.tangent.w;
  const glm::vec3 ts = glm::vec3(texel) * 2.0f - 1.0f;
  const glm::vec3 p = glm::normalize(t * (ts.x * scale) + b * (ts.y * scale) + n * ts.z);
  if (!std::isfinite(p.x)) return sp.normal;
  return sp.flipped ? -p : p;
}

static_assert(unsigned(Light::Kind::Spot) == LIGHT_SPOT && unsigned(Light::Kind::Directional) == LIGHT_DIRECTIONAL);

// Shadow sample i of n of a light as the shared light model (shaders/shared/lights.h) sees it from p, and
// the shadow ray towards it: to the sample point (t in [0, 1]), or to infinity for a directional light.
struct LightRay {
  shader::LightSample ls;
  Ray shadow;
  bool valid;  // false: p is the light's own position
};
LightRay lightRay(const Light& light, int i, int n, const glm::vec3& p, const glm::vec3& ng) {
  const glm::vec3 at = light.samplePoint(i, n);
  const shader::LightSample ls =
      shader::lightSample(shader::makeGpuLight(unsigned(light.kind), at, light.color, light.falloff, light.direction,
                                               light.innerConeCos, light.outerConeCos, light.range),
                          p);
  if (light.kind == Light::Kind::Directional) return {ls, spawnRay(p, ng, ls.l), true};
  const glm::vec3 toLight = at - p;
  return {ls, spawnRay(p, ng, toLight, 1.0f), glm::dot(toLight, toLight) > 0.0f};
}

}  // namespace

Tracer::Tracer(const Scene& scene, unsigned buildThreads) : scene_(scene) {
  // With instances, only the meshes they place are drawn, each stored once however often it is placed.
  instanced_ = !scene.instances.empty();
  std::vector<uint32_t> objectOf(scene.meshes.size(), kNoHit);
  std::vector<InstanceBvh::Object> objects;
  for (size_t i = 0; i < scene.instances.size(); ++i)
    if (scene.instances[i].mesh >= scene.meshes.size())
      throw Error("instance " + std::to_string(i) + " places mesh " + std::to_string(scene.instances[i].mesh) + " of " +
                  std::to_string(scene.meshes.size()));
    else objectOf[scene.instances[i].mesh] = 0;
  for (uint32_t mi = 0; mi < scene.meshes.size(); ++mi) {
    const Mesh& m = scene.meshes[mi];
    const bool light = m.material < scene.materials.size() && isLightMaterial(scene.materials[m.material]);
    // glTF MASK materials cut out by the alpha of factor, texture and vertex colour, textured or not.
    const Material* mat = m.material < scene.materials.size() ? &scene.materials[m.material] : nullptr;
    meshAlphaTested_.push_back(mat &&
                               ((mat->flags & kMaterialGltf) ? (mat->flags & kMaterialAlphaMasked) != 0 : alphaTested(m, *mat)));
    anyAlphaTested_ = anyAlphaTested_ || meshAlphaTested_.back();
    anyBaseTextured_ = anyBaseTextured_ || (m.material < scene.materials.size() && !m.texcoords.empty() &&
                                            scene.materials[m.material].texture(TextureSlot::BaseColor) != kNoTexture);
    if (instanced_) {
      if (objectOf[mi] == kNoHit) continue;  // placed nowhere
      objectOf[mi] = uint32_t(objects.size());
      objects.push_back({uint32_t(tris_.size()), m.triangleCount()});
    }
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
  if (instanced_) {
    std::vector<InstanceBvh::Placement> placements;
    for (const Instance& in : scene.instances) placements.push_back({objectOf[in.mesh], in.transform});
    instances_ = InstanceBvh(tris_, castsShadow_, objects, placements, buildThreads);
    return;
  }
  useBvh_ = tris_.size() >= kBruteForceMax;
  if (useBvh_) bvh_ = Bvh(tris_, castsShadow_, buildThreads);
}

Hit Tracer::closestTriangle(const Ray& r, IntersectMethod m) const {
  if (useBvh_) return bvh_.closest(r, m);
  if (instanced_) return instances_.closest(r, m);
  // The brief's loop: every triangle, keep the smallest positive t.
  Hit best;
  Ray q = r;
  for (uint32_t i = 0; i < tris_.size(); ++i) {
    float b1, b2;
    const float t = intersect(m, q, tris_[i], b1, b2);
    if (t > 0.0f) {
      best = {t, b1, b2, i};
      q.tMax = t;
    }
  }
  return best;
}

bool Tracer::occluded(const Ray& r, IntersectMethod m) const {
  if (useBvh_) return bvh_.occluded(r, m);
  if (instanced_) return instances_.occluded(r, m);
  for (uint32_t i = 0; i < tris_.size(); ++i) {
    float b1, b2;
    if (castsShadow_[i] && intersect(m, r, tris_[i], b1, b2) > 0.0f) return true;
  }
  return false;
}

SurfacePoint Tracer::surface(const Ray& r, const Hit& h) const {
  SurfacePoint sp;
  Triangle tri = tris_[h.prim];
  bool mirrored = false;
  if (instanced_) {  // into scene space: the vertices, as a flattened copy would hold them
    const glm::mat4& M = instances_.toScene(h.instance);
    mirrored = instances_.mirrored(h.instance);
    tri = {glm::vec3(M * glm::vec4(tri.v0, 1.0f)), glm::vec3(M * glm::vec4(tri.v1, 1.0f)),
           glm::vec3(M * glm::vec4(tri.v2, 1.0f))};
  }
  const float b0 = 1.0f - h.b1 - h.b2;
  sp.position = b0 * tri.v0 + h.b1 * tri.v1 + h.b2 * tri.v2;
  glm::vec3 ng = glm::cross(tri.v1 - tri.v0, tri.v2 - tri.v0);
  const float len = glm::length(ng);
  ng = len > 0.0f ? ng / len : -glm::normalize(r.direction);
  const Mesh& m = scene_.meshes[triMesh_[h.prim]];
  const uint32_t* idx = &m.indices[size_t(triLocal_[h.prim]) * 3];
  glm::vec3 ns = ng;
  if (m.normals.size() == m.positions.size()) {
    glm::vec3 n = b0 * m.normals[idx[0]] + h.b1 * m.normals[idx[1]] + h.b2 * m.normals[idx[2]];
    if (instanced_) n = instances_.normalToScene(h.instance) * n;
    const float nl = glm::length(n);
    if (nl > 0.0f && std::isfinite(nl)) ns = n / nl;
  }
  if (m.texcoords.size() == m.positions.size()) {
    const glm::vec2 t0 = m.texcoords[idx[0]], e1 = m.texcoords[idx[1]] - t0, e2 = m.texcoords[idx[2]] - t0;
    sp.uv = t0 + h.b1 * e1 + h.b2 * e2;
    if (len > 0.0f) sp.uvScale = std::sqrt(std::abs(e1.x * e2.y - e1.y * e2.x) / len);  // both doubled areas
  }
  if (m.texcoords1.size() == m.positions.size())
    sp.uv1 = b0 * m.texcoords1[idx[0]] + h.b1 * m.texcoords1[idx[1]] + h.b2 * m.texcoords1[idx[2]];
  if (m.colors.size() == m.positions.size()) sp.color = b0 * m.colors[idx[0]] + h.b1 * m.colors[idx[1]] + h.b2 * m.colors[idx[2]];
  if (m.tangents.size() == m.positions.size()) {
    glm::vec4 t = b0 * m.tangents[idx[0]] + h.b1 * m.tangents[idx[1]] + h.b2 * m.tangents[idx[2]];
    glm::vec3 x(t);
    if (instanced_) x = glm::mat3(instances_.toScene(h.instance)) * x;
    const float tl = glm::length(x);
    // A mirroring placement turns the bitangent's handedness.
    if (tl > 0.0f && std::isfinite(tl)) sp.tangent = glm::vec4(x / tl, (t.w < 0.0f) != mirrored ? -1.0f : 1.0f);
  }
  // Front = counter-clockwise as seen (glTF; a mirroring placement turns it).
  sp.backFace = (glm::dot(ng, r.direction) > 0.0f) != mirrored;
  // Two-sided: face the normals towards where the ray came from.
  if (glm::dot(ng, r.direction) > 0.0f) ng = -ng;
  sp.flipped = glm::dot(ns, ng) < 0.0f;
  if (sp.flipped) ns = -ns;
  sp.geomNormal = ng;
  sp.normal = ns;
  static const Material kDefault{};
  sp.material = m.material < scene_.materials.size() ? &scene_.materials[m.material] : &kDefault;
  sp.mesh = triMesh_[h.prim];
  return sp;
}

float Tracer::gltfAlpha(const SurfacePoint& sp, const Ray& r, float coneWidth, const Frame& f) const {
  const Material& m = *sp.material;
  const bool textured = f.tex && !scene_.meshes[sp.mesh].texcoords.empty();
  return m.opacity * sp.color.a * (textured ? f.tex->alpha(m, {sp.uv, sp.uv1}, uvWidth(sp, r, coneWidth)) : 1.0f);
}

bool Tracer::cutOut(const SurfacePoint& sp, const Ray& r, float coneWidth, const Frame& f, bool cull) const {
  const Material& m = *sp.material;
  if (m.flags & kMaterialGltf) {
    if (cull && sp.backFace && !(m.flags & kMaterialDoubleSided)) return true;
    return (m.flags & kMaterialAlphaMasked) && gltfAlpha(sp, r, coneWidth, f) < m.alphaCutoff;
  }
  return f.tex && meshAlphaTested_[sp.mesh] && f.tex->alpha(m, {sp.uv, sp.uv1}, uvWidth(sp, r, coneWidth)) < 0.5f;
}

Tracer::Visible Tracer::closestVisible(const Ray& r, const Cone& cone, const Frame& f, Counters& c, const Hit* first) const {
  Visible v{r, first ? *first : closestTriangle(r, f.s->intersect), {}, cone.width};
  v.t = v.hit.t;
  for (int layer = 0; v.hit.hit(); ++layer) {
    v.sp = surface(v.ray, v.hit);
    if (layer > 0) v.t = glm::dot(v.sp.position - r.origin, r.direction) / glm::dot(r.direction, r.direction);
    if (f.tex) v.coneWidth = cone.width + cone.spread * glm::distance(r.origin, v.sp.position);
    if (layer == kMaxAlphaLayers || !cutOut(v.sp, v.ray, v.coneWidth, f, true)) break;
    v.ray = beyond(v.ray, v.hit, v.sp);
    v.hit = closestTriangle(v.ray, f.s->intersect);
    ++c.alpha;
  }
  return v;
}

// The any-hit query, except in scenes with alpha-tested materials: there a cut-out texel must not
// block, so closest hits are taken one after another, past cut-outs and past the lights' own geometry.
bool Tracer::shadowed(const Ray& r, const Frame& f, Counters& c) const {
  ++c.shadow;
  if (!f.tex || !anyAlphaTested_) return occluded(r, f.s->intersect);
  Ray seg = r;
  for (int layer = 0;; ++layer) {
    const Hit h = closestTriangle(seg, f.s->intersect);
    if (!h.hit()) return false;
    const SurfacePoint sp = surface(seg, h);
    // A point light casts a sharp shadow: the mask at full resolution (a cone of width 0).
    if (layer == kMaxAlphaLayers || (castsShadow_[h.prim] && !cutOut(sp, seg, 0.0f, f, false))) return true;
    seg = beyond(seg, h, sp);
    ++c.alpha;
  }
}

glm::vec3 Tracer::local(const Ray& r, const SurfacePoint& sp, float coneWidth, const Frame& f, Counters& c,
                        const Shadows* pre) const {
  const TraceSettings& s = *f.s;
  const Material& mat = *sp.material;
  const glm::vec3 v = -glm::normalize(r.direction);
  const bool pbr = s.shading == Shading::Pbr;
  // A light's own surface shows its emission only (it does not light itself), in the course's model.
  if (!pbr && isLightMaterial(mat)) return mat.ke;
  // Phong takes Kd from the base colour (Kd x map_Kd) where a model textures it.
  const bool baseTextured = mat.texture(TextureSlot::BaseColor) != kNoTexture;
  const bool textured = f.tex && !scene_.meshes[sp.mesh].texcoords.empty() && (pbr || baseTextured);
  const SurfaceUv uvs{sp.uv, sp.uv1};
  const float width = textured ? uvWidth(sp, r, coneWidth) : 0.0f;
  SurfaceInputs in = textured ? f.tex->fetch(mat, uvs, width) : materialFactors(mat);
  const bool gltf = (mat.flags & kMaterialGltf) != 0;
  glm::vec3 normal = sp.normal;
  float occlusion = 1.0f;
  in.baseColor *= glm::vec3(sp.color);  // vertex colours (glTF COLOR_0, OBJ `v x y z r g b`), as the GPU
  if (gltf) {
    if (mat.flags & kMaterialUnlit) return in.baseColor;  // KHR_materials_unlit: the base colour is the result
    if (textured) {
      normal = normalMapped(sp, f.tex->sample(mat, TextureSlot::NormalMap, uvs, width, glm::vec4(-1.0f)), mat.normalScale);
      occlusion =
          1.0f + mat.occlusionStrength * (f.tex->sample(mat, TextureSlot::Occlusion, uvs, width, glm::vec4(1.0f)).r - 1.0f);
    }
  }
  // glTF materials have no Kd: Phong takes their base colour.
  const glm::vec3 kd = (textured && baseTextured) || gltf ? in.baseColor : mat.kd;
  const bool ggx = s.brdf ? *s.brdf == Brdf::Ggx : gltf;
  const int brdf = ggx ? BRDF_GGX : BRDF_BECKMANN;
  // Ambient (times the occlusion texture's) and emission, then every light's direct term averaged over its
  // shadow samples; with shadows on, a sample behind the surface itself or blocked gives nothing (Phong
  // keeps its ambient Ka x Lc).
  glm::vec3 color = pbr ? f.ambient * glm::clamp(in.baseColor, 0.0f, 1.0f) * occlusion + in.emissive : mat.ke;
  const int n = std::max(1, s.areaLightSamples);
  size_t slot = 0;
  for (const Light& light : f.lights) {
    if (!pbr) color += blinnPhongAmbient(mat, light.color);
    const int samples = light.kind == Light::Kind::Area ? n : 1;
    glm::vec3 direct(0.0f);
    for (int i = 0; i < samples; ++i, ++slot) {
      const LightRay lr = lightRay(light, i, samples, sp.position, sp.geomNormal);
      if (!lr.valid) continue;
      const shader::LightSample& ls = lr.ls;
      const glm::vec3 d = pbr ? pbrDirect(brdf, normal, v, ls.l, ls.radiance, in.baseColor, in.roughness, in.metalness)
                              : blinnPhongDirect(mat, kd, normal, v, ls.l, ls.radiance);
      if (d == glm::vec3(0.0f)) continue;
      if (s.shadows) {
        if (glm::dot(sp.geomNormal, ls.l) <= 0.0f) continue;
        if (pre && (pre->known[slot] >> pre->lane & 1)) {
          ++c.shadow;
          if (pre->blocked[slot] >> pre->lane & 1) continue;
        } else if (shadowed(lr.shadow, f, c)) {
          continue;
        }
      }
      direct += d;
    }
    color += direct / float(samples);
  }
  if (f.env) color += occlusion * environmentLight(sp, normal, v, in, brdf, f, c);
  return color;
}

void Tracer::shadowPackets(const Visible* vis, int n, const Frame& f, std::vector<uint8_t>& known,
                           std::vector<uint8_t>& blocked) const {
  const TraceSettings& s = *f.s;
  known.clear();
  blocked.clear();
  const bool pbr = s.shading == Shading::Pbr;
  // Alpha-tested scenes take shadow rays as chains of closest hits (shadowed()): those stay single.
  if (!useBvh_ || !s.shadows || (!pbr && s.shading != Shading::Phong) || (f.tex && anyAlphaTested_)) return;
  const int ns = std::max(1, s.areaLightSamples);
  for (const Light& light : f.lights) {
    const int samples = light.kind == Light::Kind::Area ? ns : 1;
    for (int i = 0; i < samples; ++i) {
      // local()'s conditions for a shadow ray, but not whether the light's term is zero (that needs the
      // material's inputs): such a ray is traced for nothing, its answer unused.
      std::array<Ray, 8> rays;
      int lanes[8], m = 0;
      for (int k = 0; k < n; ++k) {
        const Visible& v = vis[k];
        if (!v.hit.hit() || (!pbr && isLightMaterial(*v.sp.material))) continue;
        const LightRay lr = lightRay(light, i, samples, v.sp.position, v.sp.geomNormal);
        if (!lr.valid || lr.ls.radiance == glm::vec3(0.0f) || glm::dot(v.sp.geomNormal, lr.ls.l) <= 0.0f) continue;
        rays[m] = lr.shadow;
        lanes[m++] = k;
      }
      const unsigned occ = m ? bvh_.occluded8(rays.data(), m, s.intersect) : 0u;
      uint8_t kn = 0, bl = 0;
      for (int j = 0; j < m; ++j) {
        kn = uint8_t(kn | 1u << lanes[j]);
        if (occ >> j & 1) bl = uint8_t(bl | 1u << lanes[j]);
      }
      known.push_back(kn);
      blocked.push_back(bl);
    }
  }
}

glm::vec3 Tracer::shade(const Ray& r, const Cone& cone, int bounces, const Frame& f, Counters& c, const Visible* first,
                        const Shadows* pre, int blendDepth) const {
  const TraceSettings& s = *f.s;
  const Visible vis = first ? *first : closestVisible(r, cone, f, c, nullptr);
  if (s.shading == Shading::Depth) {
    if (!vis.hit.hit()) return glm::vec3(1.0f);
    return glm::vec3(std::clamp(vis.t * glm::dot(r.direction, f.depthAxis) / f.depthFar, 0.0f, 1.0f));
  }
  // bounces == s.bounces: a camera ray, or one continuing it past a blended surface (mirrors take one off).
  if (!vis.hit.hit()) return s.shading == Shading::Normals ? s.background : missed(r.direction, bounces == s.bounces, f);
  const SurfacePoint& sp = vis.sp;
  if (s.shading == Shading::Normals) return glm::abs(sp.normal);  // the brief's "interpolation" view
  glm::vec3 col = local(vis.ray, sp, vis.coneWidth, f, c, pre);
  // glTF BLEND: alpha-composited over what the ray sees beyond (the GPU's "over" blending, in ray order).
  if ((sp.material->flags & kMaterialGltf) && (sp.material->flags & kMaterialBlend) && blendDepth < kMaxAlphaLayers) {
    const float a = std::clamp(gltfAlpha(sp, vis.ray, vis.coneWidth, f), 0.0f, 1.0f);
    if (a < 1.0f) {
      ++c.alpha;
      const glm::vec3 behind =
          shade(beyond(vis.ray, vis.hit, sp), {vis.coneWidth, cone.spread}, bounces, f, c, nullptr, nullptr, blendDepth + 1);
      col = a * col + (1.0f - a) * behind;
    }
  }
  const float m = std::clamp(sp.material->mirror, 0.0f, 1.0f);
  if (m <= 0.0f || bounces <= 0) return col;  // out of bounces: the surface's own colour
  // Task 7: reflect about the shading normal (the geometric one if that would dive under the surface).
  glm::vec3 n = sp.normal;
  glm::vec3 d = r.direction - 2.0f * glm::dot(r.direction, n) * n;
  if (glm::dot(d, sp.geomNormal) <= 0.0f) n = sp.geomNormal;
  ++c.reflection;
  // A flat mirror keeps the cone's spread; it goes on from the width it has reached (RTG ch. 20).
  const glm::vec3 reflected =
      shade(reflectRay(vis.ray, n, sp.position, sp.geomNormal), {vis.coneWidth, cone.spread}, bounces - 1, f, c);
  return (1.0f - m) * col + m * reflected;  // convex mix: no energy lost or added
}

Tracer::Frame Tracer::makeFrame(const TraceSettings& s) const {
  Frame f;
  f.s = &s;
  f.toScene = glm::inverse(s.model);
  const CameraPose pose = resolvePose(s);
  const LightRig rig = s.lights ? *s.lights : resolveLights(scene_);
  f.ambient = rig.ambient;
  f.lights = rig.lights;
  for (Light& l : f.lights)
    if (l.kind == Light::Kind::Headlight) l.position = glm::vec3(f.toScene * glm::vec4(pose.position, 1.0f));
  const glm::vec3 fwd = basis(pose).forward;
  f.depthAxis = glm::transpose(glm::mat3(s.model)) * fwd;
  f.depthFar = resolveLens(s).zFar;
  // Pbr samples the textures, Phong the base colour; every view needs the alpha masks (visibility).
  const bool shaded = s.shading == Shading::Pbr || (s.shading == Shading::Phong && anyBaseTextured_);
  f.tex = shaded || anyAlphaTested_ ? &textures() : nullptr;
  // A perspective pixel subtends atan(2·tan(fov/2) / H) (RTG ch. 20); an orthographic one is a beam of
  // constant width 2·h / H (taken into scene units through the model's scale).
  const float h = float(std::max(1u, s.height));
  if (s.lens.orthographic) f.camera = {2.0f * s.lens.orthoHalfHeight / h * glm::length(glm::vec3(f.toScene[0])), 0.0f};
  else f.camera = {0.0f, std::atan(2.0f * std::tan(glm::radians(s.lens.fovYDeg) * 0.5f) / h)};
  // A cone 2^bias times as wide: every LOD goes up by the bias.
  f.camera.width *= std::exp2(s.lodBias);
  f.camera.spread *= std::exp2(s.lodBias);
  if (s.shading == Shading::Pbr && s.environment && !s.environment->empty()) f.env = s.environment.get();
  f.dirToWorld = glm::mat3(s.model);
  f.dirToScene = glm::mat3(f.toScene);
  return f;
}

glm::vec3 Tracer::traceAndShade(const Ray& r, int bounces, const TraceSettings& s) const {
  Counters c;
  const Frame f = makeFrame(s);
  return shade(r, f.camera, bounces, f, c);
}

const SceneTextures& Tracer::textures() const {
  std::lock_guard lock(texturesMutex_);
  if (!textures_) textures_ = std::make_unique<const SceneTextures>(scene_, textureCache_);
  return *textures_;
}

CameraPose Tracer::resolvePose(const TraceSettings& s) const {
  if (s.pose) return *s.pose;
  if (scene_.defaultView) return *scene_.defaultView;  // the view the scene was baked with, as rtr-view starts
  const float aspect = float(std::max(1u, s.width)) / float(std::max(1u, s.height));
  return framingPose(scene_, s.lens, aspect, s.model);
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

RenderStats Tracer::render(const TraceSettings& s, ImageF& out, const TileCallback& onTile, std::atomic<bool>* cancel) const {
  if (s.width == 0 || s.height == 0 || s.width > 32768 || s.height > 32768)
    throw Error("image size " + std::to_string(s.width) + "x" + std::to_string(s.height) + " is out of range");
  if (s.bounces < 0 || s.bounces > 64) throw Error("bounces must be in 0..64, got " + std::to_string(s.bounces));
  if (s.spp < 1 || s.spp > 65536) throw Error("samples per pixel must be in 1..65536, got " + std::to_string(s.spp));
  const Frame frame = makeFrame(s);  // loads the textures on the first pbr render: not part of its time
  const auto start = std::chrono::steady_clock::now();
  out.width = s.width;
  out.height = s.height;
  out.pixels.assign(size_t(s.width) * s.height, glm::vec4(s.background, 1.0f));

  const CameraPose pose = resolvePose(s);
  const float aspect = float(s.width) / float(s.height);
  const uint32_t ts = std::max(4u, s.tileSize);
  const uint32_t tilesX = (s.width + ts - 1) / ts, tilesY = (s.height + ts - 1) / ts;
  RenderStats stats;
  stats.tilesTotal = tilesX * tilesY;
  std::mutex mutex;  // guards stats and the callback
  const bool debugView = s.shading == Shading::Normals || s.shading == Shading::Depth;

  parallelFor(stats.tilesTotal, s.threads, [&](size_t tile) {
    if (cancel && cancel->load(std::memory_order_relaxed)) return;
    const FlushDenormals flush;
    Counters c;
    uint64_t primary = 0;
    std::vector<uint8_t> known, blocked;
    const TileRect rect{uint32_t(tile % tilesX) * ts, uint32_t(tile / tilesX) * ts,
                        std::min(s.width, uint32_t(tile % tilesX + 1) * ts),
                        std::min(s.height, uint32_t(tile / tilesX + 1) * ts)};
    // Primary rays go through the BVH eight at a time (a packet of neighbouring pixels of a row:
    // Bvh::closest8, the same hits as one at a time), then their shadow rays, a packet per light
    // sample (Bvh::occluded8, the same answers), then each pixel is shaded on its own.
    for (uint32_t y = rect.y0; y < rect.y1; ++y)
      for (uint32_t x = rect.x0; x < rect.x1; x += 8) {
        const uint32_t n = std::min(8u, rect.x1 - x);
        std::array<Ray, 8> rays;
        for (uint32_t k = 0; k < n; ++k) {
          const CameraRay cr =
              cameraRay(pose, s.lens, aspect, pixelToNdc(float(x + k) + 0.5f, float(y) + 0.5f, s.width, s.height));
          rays[k] = {glm::vec3(frame.toScene * glm::vec4(cr.origin, 1.0f)),
                     glm::vec3(frame.toScene * glm::vec4(cr.direction, 0.0f))};
        }
        std::array<Hit, 8> first;
        if (useBvh_) bvh_.closest8(rays.data(), int(n), first.data(), s.intersect);
        std::array<Visible, 8> vis;
        for (uint32_t k = 0; k < n; ++k) vis[k] = closestVisible(rays[k], frame.camera, frame, c, useBvh_ ? &first[k] : nullptr);
        shadowPackets(vis.data(), int(n), frame, known, blocked);
        for (uint32_t k = 0; k < n; ++k) {
          const Shadows pre{known.data(), blocked.data(), int(k)};
          c.rng = Rng::forPixel(x + k, y);
          glm::vec3 col = shade(rays[k], frame.camera, s.bounces, frame, c, &vis[k], known.empty() ? nullptr : &pre);
          // Debug views hold their value as displayed: encode so that sRGB output shows it unchanged.
          if (debugView) col = {srgbToLinear(col.x), srgbToLinear(col.y), srgbToLinear(col.z)};
          out.at(x + k, y) = glm::vec4(col, 1.0f);
          ++primary;
        }
      }
    std::lock_guard lock(mutex);
    ++stats.tilesDone;
    stats.primaryRays += primary;
    stats.shadowRays += c.shadow;
    stats.reflectionRays += c.reflection;
    stats.alphaRays += c.alpha;
    stats.environmentRays += c.environment;
    if (onTile) onTile(rect);
  });
  stats.cancelled = stats.tilesDone < stats.tilesTotal;
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace rtr::trace
