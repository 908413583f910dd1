#include "scene_camera.hpp"

#include <algorithm>
#include <cstdio>

#include "scene/framing.hpp"

namespace rtr::view {
namespace {

void setPoseAndTarget(ViewState& app, const Scene& scene, const CameraPose& pose) {
  const Bounds bounds = scene.bounds();
  app.camera.setPose(pose);
  if (!bounds.empty()) app.camera.setOrbitDistance(glm::length(bounds.center() - pose.position));
}

}  // namespace

void startScene(ViewState& app, const ViewOptions& o, const Scene& scene) {
  const Bounds bounds = scene.bounds();
  CameraSpeeds speeds;
  // Cross the scene in about 5 s with Shift held.
  if (!bounds.empty()) speeds.base = glm::length(bounds.extent()) / (5.0f * speeds.fastFactor);
  app.startPose = startPose(o, scene);
  const CameraMode mode = app.camera.mode();
  app.camera = CameraController(app.startPose, speeds);
  app.camera.setMode(mode);
  app.camera.setOrbitDistance(bounds.empty() ? 1.0f : glm::length(bounds.center() - app.startPose.position));
  const render::RenderSettings s = sceneSettings(o, scene);
  app.settings.lights = s.lights;
  // Course scenes light themselves with "*light*" geometry (Blinn-Phong); others use the renderer's light.
  const bool geometryLights =
      std::any_of(scene.materials.begin(), scene.materials.end(), [](const Material& m) { return m.flags & kMaterialLight; });
  app.traceShading = geometryLights ? trace::Shading::Phong : trace::Shading::Pbr;
  // The speed depends on the scene; printed so that users (and the window test) know what W does.
  std::fprintf(stderr, "rtr-view: move speed %.9g units/s (Shift x%g, Ctrl x%g)\n", speeds.base, speeds.fastFactor,
               speeds.slowFactor);
}

Lens serveCamera(ViewState& app, const Scene& scene, float aspect) {
  // F: the whole scene in view, as a scene without a stored view starts; Home: the pose the viewer started from.
  if (std::exchange(app.reframeRequested, false)) setPoseAndTarget(app, scene, framingPose(scene, app.lens, aspect));
  if (std::exchange(app.homeRequested, false)) setPoseAndTarget(app, scene, app.startPose);
  return fitDepthRange(app.lens, scene.bounds(), app.camera.pose());
}

}  // namespace rtr::view
