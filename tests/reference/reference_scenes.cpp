#include "reference_scenes.hpp"
#include "test_paths.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include <glm/geometric.hpp>
#include <glm/gtc/type_precision.hpp>

#include "core/error.hpp"
#include "core/image.hpp"
#include "scene/load.hpp"

namespace rtr::reftest {
namespace {

// Appends a triangle wound counter-clockwise about its vertex normals (the GPU culls the other side).
void addTriangle(Mesh& m, uint32_t a, uint32_t b, uint32_t c) {
  const glm::vec3 face = glm::cross(m.positions[b] - m.positions[a], m.positions[c] - m.positions[a]);
  const glm::vec3 n = m.normals[a] + m.normals[b] + m.normals[c];
  if (glm::dot(face, n) < 0.0f) std::swap(b, c);
  m.indices.insert(m.indices.end(), {a, b, c});
}

void finish(Mesh& m) {
  for (const glm::vec3& p : m.positions) m.bounds.extend(p);
}

// A flat nu x nv grid over origin + s*u + t*v, normal u x v; texcoords (s, t) when asked for.
Mesh grid(const std::string& name, uint32_t material, glm::vec3 origin, glm::vec3 u, glm::vec3 v, int nu, int nv,
          bool texcoords) {
  Mesh m;
  m.name = name;
  m.material = material;
  const glm::vec3 n = glm::normalize(glm::cross(u, v));
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const float s = float(i) / float(nu), t = float(j) / float(nv);
      m.positions.push_back(origin + s * u + t * v);
      m.normals.push_back(n);
      if (texcoords) m.texcoords.emplace_back(s, t);
    }
  auto at = [&](int i, int j) { return uint32_t(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      addTriangle(m, at(i, j), at(i + 1, j), at(i + 1, j + 1));
      addTriangle(m, at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  finish(m);
  return m;
}

// A UV sphere with smooth (analytic) normals.
Mesh sphere(const std::string& name, uint32_t material, glm::vec3 centre, float radius, int slices, int stacks) {
  Mesh m;
  m.name = name;
  m.material = material;
  for (int j = 0; j <= stacks; ++j) {
    const float theta = 3.14159265f * float(j) / float(stacks);  // from +y down
    for (int i = 0; i <= slices; ++i) {
      const float phi = 2.0f * 3.14159265f * float(i) / float(slices);
      const glm::vec3 n{std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)};
      m.positions.push_back(centre + radius * n);
      m.normals.push_back(n);
    }
  }
  auto at = [&](int i, int j) { return uint32_t(j * (slices + 1) + i); };
  for (int j = 0; j < stacks; ++j)
    for (int i = 0; i < slices; ++i) {
      if (j > 0) addTriangle(m, at(i, j), at(i + 1, j), at(i + 1, j + 1));
      if (j + 1 < stacks) addTriangle(m, at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  finish(m);
  return m;
}

Material material(const std::string& name, glm::vec3 base, float roughness, float metalness) {
  Material m;
  m.name = name;
  m.baseColor = base;
  m.roughness = roughness;
  m.metalness = metalness;
  return m;
}

// Two-sided on the GPU needs the alpha-masked pipeline (the only one that does not cull back faces): give
// the material an all-opaque alpha mask (every fragment kept) and its meshes texture coordinates. The
// tracer keeps every texel of that mask and draws both sides of every triangle, so it sees the same surface.
void twoSidedOnGpu(Scene& s, uint32_t material, const std::filesystem::path& workDir) {
  std::filesystem::create_directories(workDir);
  const std::filesystem::path mask = workDir / "opaque_mask.png";
  if (!std::filesystem::exists(mask)) savePng(mask, ImageRGBA8{4, 4, std::vector<uint8_t>(4 * 4 * 4, 255)});
  uint32_t tex = kNoTexture;
  for (uint32_t i = 0; i < s.textures.size(); ++i)
    if (s.textures[i].path == mask) tex = i;
  if (tex == kNoTexture) {
    tex = uint32_t(s.textures.size());
    s.textures.push_back({mask, false, 4});
  }
  Material& m = s.materials.at(material);
  m.flags |= kMaterialAlphaMasked | kMaterialDoubleSided;
  m.textures[uint32_t(TextureSlot::AlphaMask)] = tex;
  for (Mesh& mesh : s.meshes)
    if (mesh.material == material && mesh.texcoords.empty()) mesh.texcoords.assign(mesh.positions.size(), glm::vec2(0.0f));
}

// glTF metal-rough cases: a material as the glTF reader makes it (kMaterialGltf: GGX, its texture rules).
Material gltfMaterial(const std::string& name, glm::vec3 base, float roughness, float metalness) {
  Material m = material(name, base, roughness, metalness);
  m.flags |= kMaterialGltf;
  return m;
}

// Writes a w×h RGBA PNG into workDir and adds it as a texture (channels 1: `source` picks the channel).
uint32_t addPng(Scene& s, const std::filesystem::path& workDir, const std::string& name, uint32_t w, uint32_t h,
                const std::function<glm::u8vec4(uint32_t, uint32_t)>& texel, bool srgb, uint8_t channels = 4,
                uint8_t source = 0) {
  std::filesystem::create_directories(workDir);
  ImageRGBA8 img{w, h, std::vector<uint8_t>(size_t(w) * h * 4)};
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const glm::u8vec4 t = texel(x, y);
      std::copy_n(&t.x, 4, img.at(x, y));
    }
  const std::filesystem::path path = workDir / (name + ".png");
  savePng(path, img);
  Texture t{path, srgb, channels};
  t.sourceChannel = source;
  s.textures.push_back(t);
  return uint32_t(s.textures.size() - 1);
}

// A scene lit by its own lights (scene/lights.hpp), as the tools light it; `falloff` as --falloff.
ReferenceScene ownLights(Scene scene, bool falloff = false) {
  ReferenceScene r;
  r.scene = std::move(scene);
  LightOptions o;
  o.falloff = falloff;
  r.lights = resolveLights(r.scene, o);
  return r;
}

// Point lights at (position, colour) pairs, ambient 0.02.
LightRig pointLights(std::initializer_list<std::pair<glm::vec3, glm::vec3>> lights, bool falloff = false) {
  LightRig rig;
  for (const auto& [p, c] : lights) {
    Light l;
    l.position = p;
    l.color = c;
    l.falloff = falloff;
    rig.lights.push_back(l);
  }
  return rig;
}

// The fire cards: one-sided quads (the GPU culls their backs, the tracer draws them).
bool isFireCard(const Mesh& m) { return m.name.rfind("fire_", 0) == 0; }

}  // namespace

std::map<std::string, PoseEntry> loadPoses(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw Error(file.string() + ": cannot open");
  std::map<std::string, PoseEntry> out;
  std::string line;
  for (int lineNo = 1; std::getline(in, line); ++lineNo) {
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    const size_t hash = line.find('#');
    const std::string place = std::to_string(lineNo);
    if (hash == std::string::npos) throw fileError(file.string(), place, "a case needs a '# comment'");
    std::istringstream fields(line.substr(0, hash));
    std::string name, pose, extra;
    PoseEntry e;
    if (!(fields >> name >> pose >> e.fovYDeg) || (fields >> extra))
      throw fileError(file.string(), place, "expected 'name x,y,z,yaw,pitch fovY # comment'");
    if (!(e.fovYDeg > 1.0f && e.fovYDeg < 179.0f)) throw fileError(file.string(), place, "fovY out of range");
    try {
      e.pose = parsePose(pose);
    } catch (const Error& err) { throw fileError(file.string(), place, err.what()); }
    e.comment = line.substr(line.find_first_not_of("# \t", hash) == std::string::npos ? line.size()
                                                                                      : line.find_first_not_of("# \t", hash));
    if (e.comment.empty()) throw fileError(file.string(), place, "empty comment");
    if (!out.emplace(name, e).second) throw fileError(file.string(), place, "case '" + name + "' repeated");
  }
  return out;
}

std::filesystem::path sourceDir() { return test::sourceDir(); }

std::filesystem::path assetDir() { return test::assetDir(); }

Scene untexturedTemple(const Scene& temple, int* removed) {
  Scene s = temple;
  for (Material& m : s.materials) {
    m.textures.fill(kNoTexture);
    m.flags &= ~uint32_t(kMaterialAlphaMasked);
  }
  s.textures.clear();
  // Cards: one-sided quads (the GPU culls their backs, the tracer draws them) whose shape is the alpha mask.
  auto isCard = [&](const Mesh& m) {
    const Material* mat = m.material < s.materials.size() ? &s.materials[m.material] : nullptr;
    return (mat && (mat->flags & kMaterialDoubleSided)) || isFireCard(m);
  };
  const size_t before = s.meshes.size();
  std::erase_if(s.meshes, isCard);
  if (removed) *removed = int(before - s.meshes.size());
  return s;
}

Scene texturedTemple(const Scene& temple, const std::filesystem::path& workDir) {
  Scene s = temple;
  std::set<uint32_t> fire;
  for (const Mesh& m : s.meshes)
    if (isFireCard(m)) fire.insert(m.material);
  for (uint32_t material : fire) twoSidedOnGpu(s, material, workDir);
  return s;
}

bool isEnvironmentCase(const std::string& name) { return name.rfind("env_", 0) == 0; }

std::shared_ptr<const Environment> skyEnvironment() {
  static const auto sky = std::make_shared<const Environment>(Environment::load({.source = "sky"}));
  return sky;
}

std::shared_ptr<const Environment> sunlessSkyEnvironment() {
  static const auto sky = [] {
    ImageF m = makeSky({});
    size_t sun = 0;  // the sun's texel: the brightest by far (docs/environment.md, "Sources")
    for (size_t i = 1; i < m.pixels.size(); ++i)
      if (m.pixels[i].g > m.pixels[sun].g) sun = i;
    const uint32_t x = uint32_t(sun % m.width), y = uint32_t(sun / m.width);
    glm::vec4 around(0.0f);
    for (const auto [dx, dy] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}})
      around += m.at((x + m.width + uint32_t(dx)) % m.width, std::clamp(uint32_t(int(y) + dy), 0u, m.height - 1));
    m.at(x, y) = around / 4.0f;
    return std::make_shared<const Environment>(std::move(m), 1.0f, 0.0f);
  }();
  return sky;
}

ReferenceScene makeScene(const std::string& name, const std::filesystem::path& workDir) {
  if (isEnvironmentCase(name)) {
    // Light from the generated sky alone (no lights, no ambient); glTF materials (GGX). The tracer's
    // environment samples cast no shadow rays here (shadows off), as the GPU's split sum has none.
    ReferenceScene r;
    r.lights = LightRig{{}, glm::vec3(0.0f), {}};
    r.environment = name.ends_with("_nosun") ? sunlessSkyEnvironment() : skyEnvironment();
    Scene& s = r.scene;
    if (name == "env_metal_spheres" || name == "env_dielectric_spheres") {
      // Five spheres of roughness 0, 0.25, 0.5, 0.75, 1 in a row.
      const bool metal = name == "env_metal_spheres";
      for (int i = 0; i < 5; ++i) {
        const float rough = 0.25f * float(i);
        s.materials.push_back(gltfMaterial("r" + std::to_string(i),
                                           metal ? glm::vec3(1.0f, 0.78f, 0.34f) : glm::vec3(0.2f, 0.4f, 0.8f), rough,
                                           metal ? 1.0f : 0.0f));
        const glm::vec3 c{2.2f * float(i - 2), 0.0f, -8.0f};
        s.meshes.push_back(sphere("sphere", uint32_t(i), c, 1.0f, 96, 48));
        char label[32];
        std::snprintf(label, sizeof label, "rough %.2f", rough);
        r.parts.push_back({label, c});
      }
      return r;
    }
    if (name == "env_sphere_grid" || name == "env_sphere_grid_nosun") {
      r.scene = loadScene(assetDir() / "sphere-grid.gltf");
      for (int row = 0; row < 5; ++row)  // tools/scenegen/sphere_grid.hpp's layout
        for (int col = 0; col < 5; ++col) {
          char label[48];
          std::snprintf(label, sizeof label, "metal %.2f rough %.2f", 0.25f * float(row), 0.25f * float(col));
          r.parts.push_back({label, glm::vec3(float(col) - 2.0f, 2.0f - float(row), 0.0f)});
        }
      return r;
    }
    if (name == "env_temple") {
      r.scene = untexturedTemple(loadScene(assetDir() / "temple.rtrscene"));
      return r;
    }
    throw Error("no reference scene named '" + name + "'");
  }
  const std::filesystem::path rt = sourceDir() / "assets-src/rt";
  // The temple's stored light (the brief's standard light above the statue); the course scenes' own lights:
  // the GPU sees an area light as a point at its centre, as the tracer with one shadow sample does.
  if (name == "temple_nave" || name == "temple_aisle")
    return ownLights(untexturedTemple(loadScene(assetDir() / "temple.rtrscene")));
  if (name == "temple_nave_textured" || name == "temple_aisle_textured")
    return ownLights(texturedTemple(loadScene(assetDir() / "temple.rtrscene"), workDir));
  if (name == "cornell_box") return ownLights(loadScene(rt / "cornell_box.obj"));
  if (name == "cube_backplane" || name == "cube_backplane_falloff") {
    Scene s = loadScene(rt / "cube_backplane.obj");
    // The three emissive quads face the backplane (-z): the camera sees their backs, which the tracer draws
    // and the GPU culls. Compare the same surfaces: make them two-sided on the GPU (docs: "Culling").
    int lights = 0;
    for (uint32_t i = 0; i < s.materials.size(); ++i)
      if (s.materials[i].name.rfind("light_", 0) == 0) twoSidedOnGpu(s, i, workDir), ++lights;
    if (lights != 3) throw Error("cube_backplane: expected 3 light_* materials, found " + std::to_string(lights));
    ReferenceScene r = ownLights(std::move(s), name.ends_with("_falloff"));
    if (r.lights.lights.size() != 3) throw Error("cube_backplane: expected 3 lights");
    if (name.ends_with("_falloff"))  // the quads are 3-4 units from what they light: keep the image bright
      for (Light& l : r.lights.lights) l.color *= 12.0f;
    return r;
  }
  ReferenceScene r;
  Scene& s = r.scene;
  if (name == "grazing_floor") {
    s.materials.push_back(material("floor", {0.5f, 0.5f, 0.55f}, 0.4f, 0.0f));
    s.meshes.push_back(grid("floor", 0, {-200, 0, 200}, {400, 0, 0}, {0, 0, -400}, 16, 16, false));
    r.lights = pointLights({{{0.0f, 3.0f, -60.0f}, glm::vec3(1.0f)}});  // ahead of the camera: forward grazing specular
    return r;
  }
  if (name == "metal_sphere") {
    s.materials.push_back(material("copper", {0.95f, 0.64f, 0.54f}, 0.3f, 1.0f));
    s.meshes.push_back(sphere("sphere", 0, {0, 0, -3}, 1.0f, 96, 48));
    r.lights = pointLights({{{2.0f, 3.0f, 1.0f}, glm::vec3(2.0f)}});
    return r;
  }
  if (name == "two_lights" || name == "two_lights_falloff" || name == "headlight") {
    // A dielectric and a metal sphere on a floor, a warm key light and a cool fill from the other side.
    s.materials.push_back(material("floor", {0.6f, 0.6f, 0.6f}, 0.6f, 0.0f));
    s.materials.push_back(material("plastic", {0.2f, 0.4f, 0.8f}, 0.35f, 0.0f));
    s.materials.push_back(material("gold", {1.0f, 0.78f, 0.34f}, 0.25f, 1.0f));
    s.meshes.push_back(grid("floor", 0, {-4, -1, 0}, {8, 0, 0}, {0, 0, -8}, 8, 8, false));
    s.meshes.push_back(sphere("plastic", 1, {-1.1f, 0, -4}, 1.0f, 64, 32));
    s.meshes.push_back(sphere("gold", 2, {1.1f, 0, -4}, 1.0f, 64, 32));
    if (name == "headlight") return ownLights(std::move(s));  // no lights of its own: the default headlight
    const bool falloff = name.ends_with("_falloff");
    const float k = falloff ? 20.0f : 1.0f;  // about the squared distance to the spheres
    r.lights = pointLights(
        {{{3.0f, 3.0f, -1.0f}, k * glm::vec3(1.2f, 1.0f, 0.8f)}, {{-3.5f, 1.5f, -2.0f}, k * glm::vec3(0.3f, 0.4f, 0.6f)}},
        falloff);
    return r;
  }
  if (name == "rough0_patch") {
    s.materials.push_back(material("polished", {0.45f, 0.5f, 0.6f}, 0.0f, 0.0f));
    s.meshes.push_back(grid("patch", 0, {-1, 0, -3}, {2, 0, 0}, {0, 0, -2}, 4, 4, false));
    // Light at the mirror image of the camera about the patch centre (0, 0, -4): h = n there.
    r.lights = pointLights({{{0.0f, 1.5f, -8.0f}, glm::vec3(4.0f)}});
    return r;
  }
  if (name == "backface_quad") {
    s.materials.push_back(material("quad.DoubleSided", {0.2f, 0.6f, 0.3f}, 0.5f, 0.0f));
    s.meshes.push_back(grid("quad", 0, {-1, -1, -3}, {2, 0, 0}, {0, 2, 0}, 2, 2, true));  // faces +z
    twoSidedOnGpu(s, 0, workDir);
    r.lights = pointLights({{{1.0f, 2.0f, -7.0f}, glm::vec3(1.5f)}});  // on the camera's (back) side
    return r;
  }
  if (name == "gltf_metal_rough") {
    // A quad with a base colour texture and glTF's packed metal-rough texture (G roughness, B metalness,
    // read through Texture::sourceChannel), a GGX sphere beside it, on a floor.
    s.materials.push_back(gltfMaterial("floor", {0.5f, 0.5f, 0.5f}, 0.7f, 0.0f));
    Material q = gltfMaterial("metal_rough", glm::vec3(1.0f), 1.0f, 1.0f);
    q.textures[uint32_t(TextureSlot::BaseColor)] = addPng(
        s, workDir, "mr_base", 8, 8,
        [](uint32_t x, uint32_t y) { return glm::u8vec4(200 - 20 * x, 120 + 15 * y, 60 + 10 * (x + y), 255); }, true);
    auto packed = [](uint32_t x, uint32_t y) { return glm::u8vec4(255, 20 + 30 * x, y < 4 ? 255 : 0, 255); };
    q.textures[uint32_t(TextureSlot::Roughness)] = addPng(s, workDir, "mr_packed", 8, 8, packed, false, 1, 2);
    Texture metal = s.textures.back();  // the same image, its blue channel
    metal.sourceChannel = 3;
    s.textures.push_back(metal);
    q.textures[uint32_t(TextureSlot::Metalness)] = uint32_t(s.textures.size() - 1);
    s.materials.push_back(q);
    s.materials.push_back(gltfMaterial("ggx_gold", {1.0f, 0.78f, 0.34f}, 0.4f, 1.0f));
    s.meshes.push_back(grid("floor", 0, {-4, -1, 0}, {8, 0, 0}, {0, 0, -8}, 8, 8, false));
    s.meshes.push_back(grid("quad", 1, {-2.2f, -0.8f, -4.5f}, {2.4f, 0, 0.4f}, {0, 2.0f, 0}, 8, 8, true));
    s.meshes.push_back(sphere("sphere", 2, {1.3f, -0.2f, -4}, 0.8f, 64, 32));
    r.lights = pointLights({{{2.0f, 2.5f, -1.5f}, glm::vec3(1.6f)}, {{-2.5f, 1.0f, 0.0f}, glm::vec3(0.5f, 0.55f, 0.7f)}});
    return r;
  }
  if (name == "gltf_emissive") {
    // Emissive factor above 1 (KHR_materials_emissive_strength folds into it) times an emissive texture.
    s.materials.push_back(gltfMaterial("floor", {0.5f, 0.5f, 0.5f}, 0.7f, 0.0f));
    Material e = gltfMaterial("glow", {0.05f, 0.05f, 0.05f}, 0.6f, 0.0f);
    e.emissive = {2.5f, 1.2f, 0.3f};
    e.textures[uint32_t(TextureSlot::Emissive)] = addPng(
        s, workDir, "glow", 8, 8,
        [](uint32_t x, uint32_t y) { return glm::u8vec4((x + y) % 2 ? 255 : 90, 60 + 25 * x, 40 + 20 * y, 255); }, true);
    s.materials.push_back(e);
    s.meshes.push_back(grid("floor", 0, {-4, -1, 0}, {8, 0, 0}, {0, 0, -8}, 8, 8, false));
    s.meshes.push_back(grid("panel", 1, {-1.5f, -0.8f, -4.0f}, {3.0f, 0, 0}, {0, 1.8f, 0}, 8, 8, true));
    r.lights = pointLights({{{1.0f, 2.0f, -1.0f}, glm::vec3(0.4f)}});
    return r;
  }
  if (name == "gltf_spot") {
    // A spot light (smooth cone edge, inverse-square falloff, a range) over a floor and a sphere.
    s.materials.push_back(gltfMaterial("floor", {0.6f, 0.6f, 0.6f}, 0.6f, 0.0f));
    s.materials.push_back(gltfMaterial("ball", {0.2f, 0.5f, 0.9f}, 0.35f, 0.0f));
    s.meshes.push_back(grid("floor", 0, {-4, -1, 0}, {8, 0, 0}, {0, 0, -8}, 32, 32, false));
    s.meshes.push_back(sphere("ball", 1, {0.4f, -0.3f, -4.2f}, 0.7f, 64, 32));
    Light spot;
    spot.kind = Light::Kind::Spot;
    spot.position = {-0.5f, 2.5f, -3.5f};
    spot.direction = glm::normalize(glm::vec3(0.25f, -1.0f, -0.2f));
    spot.color = glm::vec3(14.0f, 12.0f, 10.0f);
    spot.falloff = true;
    spot.innerConeCos = std::cos(0.30f);
    spot.outerConeCos = std::cos(0.50f);
    spot.range = 8.0f;
    r.lights.lights = {spot};
    return r;
  }
  if (name == "gltf_alpha_mask") {
    // MASK: base colour alpha (the one-channel mask the reader makes of it) × opacity against alphaCutoff.
    s.materials.push_back(gltfMaterial("floor", {0.6f, 0.6f, 0.6f}, 0.6f, 0.0f));
    Material m = gltfMaterial("leaf", {0.5f, 0.9f, 0.4f}, 0.5f, 0.0f);
    m.flags |= kMaterialAlphaMasked;
    m.opacity = 0.9f;
    m.alphaCutoff = 0.4f;
    auto texel = [](uint32_t x, uint32_t y) {
      const float dx = float(x) - 7.5f, dy = float(y) - 7.5f;
      return glm::u8vec4(180, 220, 120, dx * dx + dy * dy < 40.0f ? 255 : (x / 2 + y / 2) % 2 ? 130 : 0);
    };
    m.textures[uint32_t(TextureSlot::BaseColor)] = addPng(s, workDir, "leaf", 16, 16, texel, true);
    m.textures[uint32_t(TextureSlot::AlphaMask)] = addPng(s, workDir, "leaf", 16, 16, texel, false, 1, 4);
    s.materials.push_back(m);
    s.meshes.push_back(grid("floor", 0, {-4, -1, 0}, {8, 0, 0}, {0, 0, -8}, 8, 8, false));
    s.meshes.push_back(grid("leaf", 1, {-1.2f, -0.9f, -3.5f}, {2.4f, 0, 0}, {0, 2.0f, 0}, 4, 4, true));
    r.lights = pointLights({{{1.0f, 3.0f, 0.0f}, glm::vec3(1.8f)}});
    return r;
  }
  if (name == "gltf_blend") {
    // BLEND over an opaque sphere and the floor: a panel whose base colour alpha ramps across (× opacity),
    // and in front of it one without texcoords (opacity alone); both renderers composite "over", the GPU
    // farthest first (its transparency pass), the tracer along the ray.
    s.materials.push_back(gltfMaterial("floor", {0.6f, 0.6f, 0.6f}, 0.6f, 0.0f));
    s.materials.push_back(gltfMaterial("ball", {0.9f, 0.4f, 0.2f}, 0.4f, 0.0f));
    Material glass = gltfMaterial("glass", {0.3f, 0.6f, 0.9f}, 0.3f, 0.0f);
    glass.flags |= kMaterialBlend;
    glass.opacity = 0.8f;
    auto texel = [](uint32_t x, uint32_t y) { return glm::u8vec4(200, 220, 255, uint8_t(40 + 26 * x + 2 * y)); };
    glass.textures[uint32_t(TextureSlot::BaseColor)] = addPng(s, workDir, "glass", 8, 8, texel, true);
    glass.textures[uint32_t(TextureSlot::AlphaMask)] = addPng(s, workDir, "glass", 8, 8, texel, false, 1, 4);
    s.materials.push_back(glass);
    Material tint = gltfMaterial("tint", {0.9f, 0.8f, 0.2f}, 0.5f, 0.0f);
    tint.flags |= kMaterialBlend;
    tint.opacity = 0.45f;
    s.materials.push_back(tint);
    s.meshes.push_back(grid("floor", 0, {-4, -1, 0}, {8, 0, 0}, {0, 0, -8}, 8, 8, false));
    s.meshes.push_back(sphere("ball", 1, {0.3f, -0.2f, -4.6f}, 0.7f, 64, 32));
    s.meshes.push_back(grid("glass", 2, {-1.6f, -0.8f, -3.6f}, {2.6f, 0, 0}, {0, 1.8f, 0}, 4, 4, true));
    s.meshes.push_back(grid("tint", 3, {-0.3f, -0.6f, -2.9f}, {1.6f, 0, 0}, {0, 1.1f, 0}, 2, 2, false));
    r.lights = pointLights({{{1.0f, 3.0f, 0.0f}, glm::vec3(1.8f)}});
    return r;
  }
  if (name == "gltf_normal_map" || name == "gltf_texture_transform") {
    // A normal-mapped quad with tangents, and a base colour texture under KHR_texture_transform on the
    // second uv set: built for both renderers; the GPU side is not there yet (reference_test skips them).
    s.materials.push_back(gltfMaterial("floor", {0.6f, 0.6f, 0.6f}, 0.6f, 0.0f));
    Material m = gltfMaterial("panel", {0.8f, 0.7f, 0.5f}, 0.4f, 0.0f);
    Mesh panel = grid("panel", 1, {-1.5f, -0.8f, -4.0f}, {3.0f, 0, 0}, {0, 1.8f, 0}, 8, 8, true);
    if (name == "gltf_normal_map") {
      m.textures[uint32_t(TextureSlot::NormalMap)] = addPng(
          s, workDir, "bumps", 16, 16,
          [](uint32_t x, uint32_t y) {
            const float nx = 0.5f * std::sin(float(x) * 0.8f), ny = 0.5f * std::cos(float(y) * 0.8f);
            const float nz = std::sqrt(std::max(0.0f, 1.0f - nx * nx - ny * ny));
            return glm::u8vec4(uint8_t(127.5f + 127.5f * nx), uint8_t(127.5f + 127.5f * ny), uint8_t(127.5f + 127.5f * nz), 255);
          },
          false);
      m.normalScale = 0.8f;
      panel.tangents.assign(panel.positions.size(), glm::vec4(1, 0, 0, 1));
    } else {
      m.textures[uint32_t(TextureSlot::BaseColor)] = addPng(
          s, workDir, "stripes", 8, 8,
          [](uint32_t x, uint32_t y) { return glm::u8vec4(40 + 25 * x, 200 - 20 * y, (x + y) % 3 ? 220 : 30, 255); }, true);
      UvTransform& t = m.uv[uint32_t(TextureSlot::BaseColor)];
      t.offset = {0.3f, -0.2f};
      t.rotation = 0.4f;
      t.scale = {1.5f, 0.8f};
      t.texCoord = 1;
      panel.texcoords1 = panel.texcoords;
      for (glm::vec2& uv : panel.texcoords1.writable()) uv = glm::vec2(uv.y, 1.0f - uv.x);
    }
    s.materials.push_back(m);
    s.meshes.push_back(grid("floor", 0, {-4, -1, 0}, {8, 0, 0}, {0, 0, -8}, 8, 8, false));
    s.meshes.push_back(std::move(panel));
    r.lights = pointLights({{{1.5f, 2.0f, -1.0f}, glm::vec3(1.6f)}});
    return r;
  }
  throw Error("no reference scene named '" + name + "'");
}

}  // namespace rtr::reftest
