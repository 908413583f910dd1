#pragma once
// The camera both renderers share, so that rtr-view and rtr-trace show the same image of a pose.
// Right-handed world, y up; yaw 0 and pitch 0 look down -z. Angles are in degrees: yaw turns left
// (counter-clockwise seen from +y), pitch looks up. Pixel (0,0) is the top-left corner.
#include <string>
#include <string_view>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/bounds.hpp"

namespace rtr {

struct CameraPose {
  glm::vec3 position{0.0f};
  float yawDeg = 0.0f;
  float pitchDeg = 0.0f;
};

struct Lens {
  float fovYDeg = 60.0f;  // vertical field of view (perspective)
  float zNear = 0.1f, zFar = 100.0f;
  bool orthographic = false;
  float orthoHalfHeight = 1.0f;  // orthographic volume is ±aspect·h × ±h
};

// "x,y,z,yaw,pitch" (yaw and pitch in degrees). Throws rtr::Error saying what is wrong.
CameraPose parsePose(std::string_view text);
std::string formatPose(const CameraPose& pose);  // round-trips through parsePose

struct CameraBasis {
  glm::vec3 forward, right, up;
};
CameraBasis basis(const CameraPose& pose);
glm::mat4 viewMatrix(const CameraPose& pose);
// Vulkan clip space: depth in [0,1], y pointing down in framebuffer space.
glm::mat4 projectionMatrix(const Lens& lens, float aspect);

// The ray through the point `ndc` of the image, ndc in [-1,1]² with +y up. Identical rule to the raster
// projection above, so a pixel centre's ray passes through the point the rasteriser samples there.
struct CameraRay {
  glm::vec3 origin, direction;
};
CameraRay cameraRay(const CameraPose& pose, const Lens& lens, float aspect, glm::vec2 ndc);
glm::vec2 pixelToNdc(float px, float py, uint32_t width, uint32_t height);  // px,py: pixel centre coords

// A view down -z that frames the whole of `bounds` (the course's staged scenes are authored to be seen so).
CameraPose frameBounds(const Bounds& bounds, const Lens& lens, float aspect);
// A view of the bounds' centre with this yaw and pitch, the bounding sphere inside the view.
CameraPose orbitFrame(const Bounds& bounds, const Lens& lens, float aspect, float yawDeg, float pitchDeg);
// Near and far planes that keep `bounds` inside the depth range from `pose`.
Lens fitDepthRange(Lens lens, const Bounds& bounds, const CameraPose& pose);

}  // namespace rtr
