#pragma once
// Scenes, poses and lights of the GPU-vs-CPU reference tests: the generated default scene (an untextured
// copy, and as baked), the ray tracer's course scenes, and synthetic hard views built in code.
#include <filesystem>
#include <map>
#include <string>

#include "core/camera.hpp"
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
};

// Builds the scene of a case by name (the names in poses.txt). `workDir` receives generated files (the
// back-face quad's alpha-mask texture). Throws rtr::Error for an unknown name.
ReferenceScene makeScene(const std::string& name, const std::filesystem::path& workDir);

// The default scene without textures: every texture slot cleared (both sides then use the material
// factors), and the meshes that only make sense with an alpha mask or would need two-sided drawing
// (foliage and ivy cards, the fire cards) removed. Returns how many meshes were removed in `removed`.
Scene untexturedTemple(const Scene& temple, int* removed = nullptr);
// The default scene as it is, textures and all, except that the one-sided fire cards are made two-sided
// on the GPU (the tracer draws both sides of everything; see docs "Culling"). `workDir` as for makeScene.
Scene texturedTemple(const Scene& temple, const std::filesystem::path& workDir);

}  // namespace rtr::reftest
