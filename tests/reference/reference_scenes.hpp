#pragma once
// Scenes, poses and lights of the GPU-vs-CPU reference tests: the generated default scene (an untextured
// copy, and as baked), the ray tracer's course scenes, and synthetic hard views built in code.
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "core/camera.hpp"
#include "scene/environment.hpp"
#include "scene/lights.hpp"
#include "scene/scene.hpp"
#include "trace/tracer.hpp"

namespace rtr::reftest {

// Where the sources (poses.txt, assets-src/) and the baked assets are: the build's folders, or the
// environment's RTR_SOURCE_DIR / RTR_ASSET_DIR (a bundled copy on another machine, tools/bundle_device.sh).
std::filesystem::path sourceDir();
std::filesystem::path assetDir();

struct PoseEntry {
  CameraPose pose;
  float fovYDeg = 60.0f;
  std::string comment;
};

// Parses tests/reference/poses.txt ("name x,y,z,yaw,pitch fovY # comment"). Throws rtr::Error naming the
// line for a malformed entry, a missing comment or a repeated name.
std::map<std::string, PoseEntry> loadPoses(const std::filesystem::path& file);

struct ReferenceScene {
  Scene scene;
  LightRig lights;  // both renderers light the scene with exactly these
  // Light from an environment (the env_* cases): the GPU's split sum against the tracer's Monte Carlo.
  std::shared_ptr<const Environment> environment;
  // The spheres of the sphere cases, for errors per sphere: each covered pixel belongs to the nearest
  // centre on screen.
  struct Part {
    std::string name;
    glm::vec3 centre;
  };
  std::vector<Part> parts;
};

// The environment-lit cases (poses.txt's env_*): lit by the environment alone, GGX (glTF materials).
bool isEnvironmentCase(const std::string& name);
// `rtr-view --env sky`'s environment (the generated sky, 512x256), made once.
std::shared_ptr<const Environment> skyEnvironment();
// The same sky with the sun's texel replaced by the mean of its four neighbours (the glow around it kept):
// smooth light, where the split sum's own error is small (the *_nosun cases).
std::shared_ptr<const Environment> sunlessSkyEnvironment();

// Builds the scene of a case by name (the names in poses.txt). `workDir` receives generated files (the
// back-face quad's alpha-mask texture). Throws rtr::Error for an unknown name. The env_sphere_grid case
// loads `scenegen --sphere-grid`'s glTF from the assets (built with them).
ReferenceScene makeScene(const std::string& name, const std::filesystem::path& workDir);

// The default scene without textures: every texture slot cleared (both sides then use the material
// factors), and the meshes that only make sense with an alpha mask or would need two-sided drawing
// (foliage and ivy cards, the fire cards) removed. Returns how many meshes were removed in `removed`.
Scene untexturedTemple(const Scene& temple, int* removed = nullptr);
// The default scene as it is, textures and all, except that the one-sided fire cards are made two-sided
// on the GPU (the tracer draws both sides of everything; see docs "Culling"). `workDir` as for makeScene.
Scene texturedTemple(const Scene& temple, const std::filesystem::path& workDir);

}  // namespace rtr::reftest
