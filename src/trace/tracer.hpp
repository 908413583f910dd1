#pragma once
// The CPU ray tracer: built once per scene, then renders images of it tile by tile over N threads.
// Shading follows the brief's Part 1 (Blinn-Phong with the scene's lights, shadow rays, impulse mirrors
// up to N_BOUNCES), or the GPU renderer's PBR BRDF over the same lights, or debug views (normals, depth).
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "core/camera.hpp"
#include "core/image.hpp"
#include "scene/environment.hpp"
#include "scene/lights.hpp"
#include "scene/scene.hpp"
#include "trace/bvh.hpp"
#include "trace/instances.hpp"
#include "trace/intersect.hpp"
#include "trace/ray.hpp"
#include "trace/sampling.hpp"
#include "trace/textures.hpp"

namespace rtr::trace {

constexpr int N_BOUNCES = 5;  // the brief's default recursion depth for mirrors
// Cut-out texels (alpha < 0.5) a ray passes through at most; the surface after them counts as opaque.
constexpr int kMaxAlphaLayers = 32;

enum class Shading { Phong, Pbr, Normals, Depth };
constexpr std::array<EnumName<Shading>, 4> enumNames(Shading) {
  return {{{Shading::Phong, "phong"}, {Shading::Pbr, "pbr"}, {Shading::Normals, "normals"}, {Shading::Depth, "depth"}}};
}
// pbr's BRDF (shaders/shared/brdf.h): the brief's Beckmann or glTF's GGX.
enum class Brdf { Beckmann, Ggx };
constexpr std::array<EnumName<Brdf>, 2> enumNames(Brdf) { return {{{Brdf::Beckmann, "beckmann"}, {Brdf::Ggx, "ggx"}}}; }

struct TraceSettings {
  uint32_t width = 1280, height = 720;
  std::optional<CameraPose> pose;  // none: the scene's stored view, else framingPose(scene), as the viewer
  Lens lens{};                     // the viewer's defaults (60° vertical fov); --fov 80 is the course's
  glm::mat4 model{1.0f};           // Task 1 model transform (a similarity); modelview = view × model
  Shading shading = Shading::Phong;
  bool shadows = true;
  int bounces = N_BOUNCES;  // mirror recursion depth; 0 turns reflections off
  IntersectMethod intersect = IntersectMethod::Watertight;
  unsigned threads = 0;  // 0: every core
  uint32_t tileSize = 32;
  int areaLightSamples = 1;  // shadow rays per area light: 1 aims at its centre (hard shadows)
  // The lights, in scene space, and pbr's ambient colour; none: resolveLights(scene) (scene/lights.hpp).
  // Phong's ambient is Ka x each light's colour, as the course's.
  std::optional<LightRig> lights;
  float lodBias = 0.0f;      // pbr: added to every texture's level of detail, as the GPU's bias
  std::optional<Brdf> brdf;  // pbr; none: per material, GGX for glTF materials, Beckmann for the rest
  // Light from an environment (pbr): integrated at every shaded point by multiple importance sampling of
  // the environment and the BRDF, `spp` sample pairs a pixel, each with its shadow ray; rays that miss
  // the scene see it. None: no environment light, misses see `background`.
  std::shared_ptr<const Environment> environment;
  int spp = 16;
  bool environmentVisible = true;  // false: camera rays that miss see `background` even with an environment
  glm::vec3 background{0.0f};
};

struct TileRect {
  uint32_t x0, y0, x1, y1;
};  // half-open pixel rectangle
// Called once per finished tile, never concurrently with itself (the tracer serialises the calls).
using TileCallback = std::function<void(const TileRect&)>;

struct RenderStats {
  double seconds = 0.0;
  uint64_t primaryRays = 0, shadowRays = 0, reflectionRays = 0;
  uint64_t alphaRays = 0;        // rays continued beyond a cut-out texel (pbr with alpha-tested materials)
  uint64_t environmentRays = 0;  // shadow rays of environment light samples (also counted in shadowRays)
  uint32_t tilesDone = 0, tilesTotal = 0;
  bool cancelled = false;
};

// What shading needs to know about a hit, in scene (model) space.
struct SurfacePoint {
  glm::vec3 position;    // from the barycentrics
  glm::vec3 geomNormal;  // unit, facing the incoming ray
  glm::vec3 normal;      // interpolated shading normal, unit, same side as geomNormal
  glm::vec2 uv{0.0f};
  float uvScale = 0.0f;     // √(uv area / area) of the triangle: texture-coordinate units per scene unit
  glm::vec2 uv1{0.0f};      // the second uv set (glTF TEXCOORD_1), where the mesh has one
  glm::vec4 color{1.0f};    // vertex colour (glTF COLOR_0), white without
  glm::vec4 tangent{0.0f};  // xyz unit tangent in scene space, w the bitangent's sign; zero without
  bool flipped = false;     // the normals were turned to face the ray (it hit the back of the interpolated side)
  bool backFace = false;    // the ray hit the triangle's back (clockwise as seen; glTF's culled side)
  const Material* material = nullptr;
  uint32_t mesh = 0;
};

// The brief's Task 1: the modelview matrix, view × model.
glm::mat4 modelview(const CameraPose& pose, const glm::mat4& model);

class Tracer {
 public:
  // Keeps a reference to `scene`, which must outlive the tracer. Builds a BVH unless the scene is tiny
  // (fewer than kBruteForceMax triangles: then every ray tests every triangle, as the brief's loop does);
  // a scene with instances gets the two-level InstanceBvh (each placed mesh's triangles stored once).
  explicit Tracer(const Scene& scene, unsigned buildThreads = 0);
  static constexpr size_t kBruteForceMax = 16;

  // Renders into `out` (resized to settings.width × height, linear RGBA). Returns early with
  // stats.cancelled set when *cancel becomes true. Throws rtr::Error on bad settings.
  RenderStats render(const TraceSettings& settings, ImageF& out, const TileCallback& onTile = {},
                     std::atomic<bool>* cancel = nullptr) const;

  // The pose and lens a render with these settings uses (defaults filled in from the scene bounds).
  CameraPose resolvePose(const TraceSettings& s) const;
  Lens resolveLens(const TraceSettings& s) const;

  // Task 2: the ray through the centre of pixel (px, py), in scene space (through the model transform).
  Ray calculateRay(const TraceSettings& s, uint32_t px, uint32_t py) const;
  // Task 3: the closest triangle along the ray (kNoHit when none); any shadow caster along it.
  Hit closestTriangle(const Ray& r, IntersectMethod m = IntersectMethod::Watertight) const;
  bool occluded(const Ray& r, IntersectMethod m = IntersectMethod::Watertight) const;
  SurfacePoint surface(const Ray& r, const Hit& h) const;
  // Task 7's TraceAndShadeWithRay: colour seen along r with `bounces` mirror bounces left. Textures are
  // filtered for the ray cone of one pixel of `s` starting at r's origin.
  glm::vec3 traceAndShade(const Ray& r, int bounces, const TraceSettings& s) const;

  // The textures pbr shading samples, loaded on the first call (the first pbr render); no other shading
  // loads any. Thread-safe. Throws rtr::Error naming a texture file that is missing or undecodable.
  const SceneTextures& textures() const;
  // Where textures() looks for chains first and stores those it makes (null: nowhere); set before the
  // first pbr render, and it must outlive the tracer.
  void setTextureCache(TextureCache* cache) { textureCache_ = cache; }

  // Each drawn mesh's triangles once (object space where the scene has instances).
  const std::vector<Triangle>& triangles() const { return tris_; }
  bool usesBvh() const { return useBvh_; }
  bool instanced() const { return instanced_; }
  const Bvh& bvh() const { return bvh_; }
  const Scene& scene() const { return scene_; }

 private:
  struct Counters {
    uint64_t shadow = 0, reflection = 0, alpha = 0, environment = 0;
    Rng rng;  // the pixel's own (Rng::forPixel), reset by the render loop before each pixel
  };
  // A ray cone (Akenine-Möller et al., Ray Tracing Gems ch. 20) for texture LOD: width at the ray's
  // origin, growing by `spread` (radians) per unit of distance.
  struct Cone {
    float width = 0.0f, spread = 0.0f;
  };
  // Per-render constants in scene space.
  struct Frame {
    const TraceSettings* s;
    glm::mat4 toScene;          // inverse of the model transform
    std::vector<Light> lights;  // in scene space; a headlight placed at the camera
    glm::vec3 ambient{0.0f};    // pbr
    glm::vec3 depthAxis;        // t · dot(d, depthAxis) = distance along the camera's forward axis
    float depthFar;
    const SceneTextures* tex = nullptr;            // pbr only
    Cone camera;                                   // a primary ray's cone
    const Environment* env = nullptr;              // pbr with a non-empty environment
    glm::mat3 dirToWorld{1.0f}, dirToScene{1.0f};  // directions between scene space and the environment's
  };
  // A hit with its surface and the cone's width there; `ray` is the segment it was found on, t the hit's
  // parameter along the first ray (past cut-outs, of the hit point projected onto it).
  struct Visible {
    Ray ray;
    Hit hit;
    SurfacePoint sp;
    float coneWidth = 0.0f;
    float t = 0.0f;
  };
  // Shadow answers the render loop traced ahead for a packet's pixels: slot j is the j-th light sample
  // of local()'s loop, bit `lane` of known[j] says it was traced, of blocked[j] that it is occluded.
  struct Shadows {
    const uint8_t* known;
    const uint8_t* blocked;
    int lane;
  };
  Frame makeFrame(const TraceSettings& s) const;
  // `first`: what r sees when the caller has traced it already (the render loop traces primary rays in
  // packets), else null; `pre`: shadow rays traced ahead for it, else null.
  // `blendDepth`: glTF BLEND surfaces composited in front of this ray already (at most kMaxAlphaLayers).
  glm::vec3 shade(const Ray& r, const Cone& cone, int bounces, const Frame& f, Counters& c, const Visible* first = nullptr,
                  const Shadows* pre = nullptr, int blendDepth = 0) const;
  glm::vec3 local(const Ray& r, const SurfacePoint& sp, float coneWidth, const Frame& f, Counters& c,
                  const Shadows* pre = nullptr) const;
  // The shadow rays local() will ask for at these n ≤ 8 hits, traced as packets, one per light sample
  // (all go to the same point): known/blocked as in Shadows, left empty where local() must trace alone.
  void shadowPackets(const Visible* vis, int n, const Frame& f, std::vector<uint8_t>& known, std::vector<uint8_t>& blocked) const;
  // Whether a ray passes this hit: a cut-out texel; for glTF materials MASK below the cutoff and, with
  // `cull` (what the camera and mirrors see, not shadow rays), the back of a single-sided material.
  bool cutOut(const SurfacePoint& sp, const Ray& r, float coneWidth, const Frame& f, bool cull) const;
  // glTF materials: the alpha, opacity × base colour alpha × vertex alpha.
  float gltfAlpha(const SurfacePoint& sp, const Ray& r, float coneWidth, const Frame& f) const;
  // The environment's light reflected towards v at sp (f.env set): the MIS estimate, s.spp pairs of one
  // environment sample and one BRDF sample, power heuristic, each with a shadow ray (env_light.cpp).
  glm::vec3 environmentLight(const SurfacePoint& sp, const glm::vec3& n, const glm::vec3& v, const SurfaceInputs& in, int brdf,
                             const Frame& f, Counters& c) const;
  // What a ray that leaves the scene in (scene-space) direction d sees; camera: a camera ray (or one
  // continuing it through a cut-out or a blended surface), not a mirror's.
  glm::vec3 missed(const glm::vec3& d, bool camera, const Frame& f) const;
  Visible closestVisible(const Ray& r, const Cone& cone, const Frame& f, Counters& c, const Hit* first) const;
  bool shadowed(const Ray& r, const Frame& f, Counters& c) const;

  const Scene& scene_;
  std::vector<Triangle> tris_;
  std::vector<uint32_t> triMesh_, triLocal_;  // triangle → mesh, triangle index within the mesh
  std::vector<uint8_t> castsShadow_;
  std::vector<uint8_t> meshAlphaTested_;  // per mesh: scene/textures.hpp's alphaTested
  bool anyAlphaTested_ = false;
  bool anyBaseTextured_ = false;  // a mesh with texcoords whose material has a base colour texture
  Bvh bvh_;
  bool useBvh_ = false;
  InstanceBvh instances_;
  bool instanced_ = false;
  mutable std::mutex texturesMutex_;
  mutable std::unique_ptr<const SceneTextures> textures_;
  TextureCache* textureCache_ = nullptr;
};

}  // namespace rtr::trace
