// Choosing a level of detail per cluster (docs/virtual-geometry.md), the same rule on the GPU's culling
// pass and in the CPU's tests: a cluster is drawn when the error of the simplification that made it,
// seen from the eye, is at most the threshold, and the error of the one that replaced it (its parent
// group's) is above. Both errors are object-space distances bounded by spheres; a parent's error and
// sphere contain its children's, so the projected parent error is never below the child's and every
// path from a root to a leaf crosses the threshold exactly once: one cut, no cracks (group borders were
// locked while simplifying).
#ifndef RTR_SHADERS_SHARED_CLUSTER_LOD_H
#define RTR_SHADERS_SHARED_CLUSTER_LOD_H

#include "shared.h"
#ifdef __cplusplus
namespace rtr::shader {
using namespace glm;
#endif

// An error that no threshold accepts: the parent of a root.
RTR_CONST float LOD_ERROR_INFINITE = 3.0e38f;

// Pixels an object-space error spans at the nearest point of `sphere` (xyz centre, w radius) seen from
// `eye`; `pixelsPerUnit` = viewport height / (2 tan(fovY / 2)). Inside the sphere: as if at `zNear`.
RTR_FN float lodProjectedError(vec4 sphere, float error, vec3 eye, float pixelsPerUnit, float zNear) {
  if (error >= LOD_ERROR_INFINITE) return LOD_ERROR_INFINITE;
  float d = max(length(vec3(sphere) - eye) - sphere.w, zNear);
  return error / d * pixelsPerUnit;
}

// Whether the cluster is part of the cut at `threshold` pixels.
RTR_FN bool lodSelected(vec4 sphere, float error, vec4 parentSphere, float parentError, vec3 eye,
                        float pixelsPerUnit, float zNear, float threshold) {
  return lodProjectedError(sphere, error, eye, pixelsPerUnit, zNear) <= threshold &&
         lodProjectedError(parentSphere, parentError, eye, pixelsPerUnit, zNear) > threshold;
}

#ifdef __cplusplus
}  // namespace rtr::shader
#endif
#endif
