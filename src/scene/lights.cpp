#include "scene/lights.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace rtr {

Light briefLight() {
  Light l;
  l.position = {-0.2972f, 7.3100f, -11.9532f};
  return l;
}

bool isLightMaterial(const Material& m) { return (m.flags & kMaterialLight) != 0 || m.name.find("light") != std::string::npos; }

glm::vec3 Light::samplePoint(int i, int n) const {
  if (kind != Kind::Area || n <= 1) return position;
  const int side = std::max(1, int(std::lround(std::sqrt(double(n)))));
  const float s = (float(i % side) + 0.5f) / float(side), t = (float((i / side) % side) + 0.5f) / float(side);
  return corner + s * edge1 + t * edge2;
}

namespace {

Light areaLight(const Mesh& m, glm::vec3 color) {
  const uint32_t* f0 = &m.indices[0];
  const uint32_t* f1 = &m.indices[3];
  Light l;
  l.kind = Light::Kind::Area;
  l.color = color;
  const glm::vec3 a = m.positions[f0[0]], b = m.positions[f0[1]], c = m.positions[f0[2]];
  l.normal = glm::cross(b - a, c - a);
  const float len = glm::length(l.normal);
  l.normal = len > 0.0f ? l.normal / len : glm::vec3(0, 0, 1);
  // The corner of the first face that is not on the diagonal it shares with the second face.
  auto inSecond = [&](uint32_t idx) {
    const glm::vec3 p = m.positions[idx];
    for (int k = 0; k < 3; ++k)
      if (m.positions[f1[k]] == p) return true;
    return false;
  };
  int corner = -1;
  for (int k = 0; k < 3; ++k)
    if (!inSecond(f0[k]) && inSecond(f0[(k + 1) % 3]) && inSecond(f0[(k + 2) % 3])) corner = k;
  if (corner < 0) corner = 0;  // not a quad: treat the first face as the parallelogram's half
  l.corner = m.positions[f0[corner]];
  l.edge1 = m.positions[f0[(corner + 1) % 3]] - l.corner;
  l.edge2 = m.positions[f0[(corner + 2) % 3]] - l.corner;
  l.position = l.corner + 0.5f * (l.edge1 + l.edge2);
  return l;
}

}  // namespace

// A light material's colour: its Ke, or its Kd when it has no Ke (exporters often write the colour there).
glm::vec3 lightColor(const Material& m) { return m.ke != glm::vec3(0.0f) ? m.ke : m.kd; }

std::vector<Light> lightsFromGeometry(const Scene& scene) {
  std::vector<Light> lights;
  for (const Mesh& m : scene.meshes) {
    if (m.material >= scene.materials.size() || m.positions.empty()) continue;
    const Material& mat = scene.materials[m.material];
    if (!isLightMaterial(mat)) continue;
    if (m.triangleCount() == 2) {
      lights.push_back(areaLight(m, lightColor(mat)));
      continue;
    }
    Light l;
    glm::dvec3 sum(0.0);
    for (const glm::vec3& p : m.positions) sum += glm::dvec3(p);
    l.position = glm::vec3(sum / double(m.positions.size()));
    l.color = lightColor(mat);
    lights.push_back(l);
  }
  return lights;
}

bool hasOwnLights(const Scene& scene) { return !scene.lights.empty() || !lightsFromGeometry(scene).empty(); }

LightRig resolveLights(const Scene& scene, const LightOptions& o) {
  LightRig rig;
  rig.ambient = o.ambient;
  if (o.position) {
    Light l;
    l.position = *o.position;
    l.color = o.color;
    rig.lights = {l};
    rig.note = "lit by --light";
  } else {
    rig.lights = scene.lights.empty() ? lightsFromGeometry(scene) : scene.lights;
  }
  if (rig.lights.size() > kMaxLights) {
    rig.note =
        "the scene has " + std::to_string(rig.lights.size()) + " lights; the first " + std::to_string(kMaxLights) + " are used";
    rig.lights.resize(kMaxLights);
  }
  for (Light& l : rig.lights) l.falloff = l.falloff || o.falloff;
  // Lights that are all black would give a black image: the headlight instead, said why.
  const bool allBlack =
      !o.position && !rig.lights.empty() &&
      std::all_of(rig.lights.begin(), rig.lights.end(), [](const Light& l) { return l.color == glm::vec3(0.0f); });
  if (allBlack && o.defaultLight) rig.lights.clear();
  if (rig.lights.empty() && o.defaultLight) {
    Light h;
    h.kind = Light::Kind::Headlight;
    rig.lights = {h};
    rig.note = allBlack ? "the scene's lights are all black (zero colour): lit by a headlight at the camera instead "
                          "(--no-default-light: none)"
                        : "the scene has no lights: lit by a headlight at the camera (--no-default-light: none)";
  } else if (rig.lights.empty()) {
    rig.note = "the scene has no lights and --no-default-light is set: only ambient and emission light it";
  }
  return rig;
}

}  // namespace rtr
