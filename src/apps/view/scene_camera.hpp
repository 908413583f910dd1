#pragma once
// The camera's part of the window: where a scene starts (pose, speeds, lights, the tracer's shading) and
// the one-shot camera requests (F frames the scene, Home returns to the start pose).
#include "options.hpp"
#include "view_state.hpp"

namespace rtr::view {

// Camera, speeds and lights for a newly loaded scene (o.camera applies as given: clear it after the first).
void startScene(ViewState& app, const ViewOptions& o, const Scene& scene);
// Serves F and Home; returns the lens for this frame, its depth range fitted to the scene.
Lens serveCamera(ViewState& app, const Scene& scene, float aspect);

}  // namespace rtr::view
