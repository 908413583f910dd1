#pragma once
// What every tool does with a file before its first picture, one rule for rtr-view, rtr-trace and rtr-bake
// (docs/viewer.md, "The first picture"): which axis is up, which shading model a scene is meant for,
// which sides are drawn, and the one-line warning when an image shows nothing.
#include <string>
#include <string_view>

#include <glm/mat3x3.hpp>

#include "core/camera.hpp"
#include "scene/scene.hpp"

namespace rtr {

// --up +X|+Y|+Z|-X|-Y|-Z: the rotation that turns that axis into +Y (the tools' up). Throws
// rtr::UsageError naming the option for anything else.
glm::mat3 upRotation(std::string_view axis);
// Turns the scene (meshes or their placements, lights) by `r`; a stored view no longer fits and is dropped.
void turnScene(Scene& scene, const glm::mat3& r);

// One of the course's ray-tracer scenes: it lights itself with `*light*` geometry, or its MTL uses the
// course's mirror or refraction keys (N_mirr > 0, N_ior other than 1). Those are shaded with the course's
// Blinn-Phong by default; everything else with PBR.
bool isCourseScene(const Scene& scene);

// Models are drawn from both sides in every tool, as other model viewers draw them (the tracer sees both
// sides anyway): a scene that is not a course scene, whose materials say nothing about sides (no
// `.DoubleSided` name, not glTF), gets every material two-sided. True when it changed anything.
bool drawBothSides(Scene& scene);

// The warning for an image that shows nothing ("" when it shows something): the scene's bounds wholly
// outside the view, or no lit pixel (`lightCount`: the lights used, 0 with --no-default-light).
std::string emptyImageWarning(const Scene& scene, const CameraPose& pose, const Lens& lens, float aspect, bool anyLitPixel,
                              size_t lightCount);

}  // namespace rtr
