#pragma once
// The pose that frames a scene when no pose is given, the same for rtr-view and rtr-trace.
#include <span>
#include <vector>

#include <glm/mat4x4.hpp>

#include "core/camera.hpp"
#include "scene/scene.hpp"

namespace rtr {

// A staged scene (it brings its own lights, like the course's Cornell box) is seen level from one side,
// as the course shows its scenes down -z: an open side of its bounding box first (a box open to the
// front), then the side its lights are on or shine to, then +z. A bare model is seen from above at a
// three-quarter angle (35° to the right, 25° down) so a solid reads as a solid, unless another of the
// four three-quarter views from above sees clearly more of its front faces (a single sheet seen from
// behind or edge-on would show nothing); from below only when no face is wound towards any view from
// above (a sheet that faces down). `model` places the scene in the world (the
// tracer's Task 1 transform; a similarity).
CameraPose framingPose(const Scene& scene, const Lens& lens, float aspect, const glm::mat4& model = glm::mat4(1.0f));

// The level view of a staged scene from `side` (+z, -z, +x or -x), the scene framed as frameBounds does.
CameraPose stagedFrame(const Scene& scene, const Lens& lens, float aspect, const glm::vec3& side);

// Front-facing area of the scene's triangles projected on the plane facing `toViewer` (scene space).
double frontArea(const Scene& scene, const glm::vec3& toViewer);
// The same for several directions in one pass over the triangles.
// `windingOnly`: two-sided materials count only their front too.
std::vector<double> frontAreas(const Scene& scene, std::span<const glm::vec3> toViewer, bool windingOnly = false);

}  // namespace rtr
