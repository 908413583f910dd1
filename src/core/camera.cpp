#include "core/camera.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "core/error.hpp"

namespace rtr {

CameraPose parsePose(std::string_view text) {
  std::vector<float> v;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find(',', start);
    if (end == std::string_view::npos) end = text.size();
    std::string field(text.substr(start, end - start));
    char* stop = nullptr;
    float f = std::strtof(field.c_str(), &stop);
    if (field.empty() || *stop != '\0' || !std::isfinite(f))
      throw Error("camera pose '" + std::string(text) + "': field " + std::to_string(v.size() + 1) + " ('" + field +
                  "') is not a finite number; expected x,y,z,yaw,pitch");
    v.push_back(f);
    start = end + 1;
  }
  if (v.size() != 5)
    throw Error("camera pose '" + std::string(text) + "': expected 5 numbers x,y,z,yaw,pitch, got " + std::to_string(v.size()));
  return {{v[0], v[1], v[2]}, v[3], v[4]};
}

std::string formatPose(const CameraPose& p) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%.9g,%.9g,%.9g,%.9g,%.9g", p.position.x, p.position.y, p.position.z, p.yawDeg, p.pitchDeg);
  return buf;
}

CameraBasis basis(const CameraPose& p) {
  const float yaw = glm::radians(p.yawDeg), pitch = glm::radians(p.pitchDeg);
  const glm::vec3 forward{-std::sin(yaw) * std::cos(pitch), std::sin(pitch), -std::cos(yaw) * std::cos(pitch)};
  const glm::vec3 right{std::cos(yaw), 0.0f, -std::sin(yaw)};  // horizontal: the camera never rolls
  return {forward, right, glm::cross(right, forward)};
}

glm::mat4 viewMatrix(const CameraPose& p) {
  const CameraBasis b = basis(p);
  glm::mat4 m(1.0f);  // rows are the camera axes; camera looks down its -z
  m[0][0] = b.right.x;
  m[1][0] = b.right.y;
  m[2][0] = b.right.z;
  m[0][1] = b.up.x;
  m[1][1] = b.up.y;
  m[2][1] = b.up.z;
  m[0][2] = -b.forward.x;
  m[1][2] = -b.forward.y;
  m[2][2] = -b.forward.z;
  m[3][0] = -glm::dot(b.right, p.position);
  m[3][1] = -glm::dot(b.up, p.position);
  m[3][2] = glm::dot(b.forward, p.position);
  return m;
}

glm::mat4 projectionMatrix(const Lens& lens, float aspect) {
  glm::mat4 m = lens.orthographic ? glm::orthoRH_ZO(-aspect * lens.orthoHalfHeight, aspect * lens.orthoHalfHeight,
                                                    -lens.orthoHalfHeight, lens.orthoHalfHeight, lens.zNear, lens.zFar)
                                  : glm::perspectiveRH_ZO(glm::radians(lens.fovYDeg), aspect, lens.zNear, lens.zFar);
  m[1][1] = -m[1][1];  // Vulkan's framebuffer y points down
  return m;
}

glm::vec2 pixelToNdc(float px, float py, uint32_t width, uint32_t height) {
  return {2.0f * px / float(width) - 1.0f, 1.0f - 2.0f * py / float(height)};
}

CameraRay cameraRay(const CameraPose& pose, const Lens& lens, float aspect, glm::vec2 ndc) {
  const CameraBasis b = basis(pose);
  if (lens.orthographic) {
    const glm::vec3 o = pose.position + b.right * (ndc.x * aspect * lens.orthoHalfHeight) + b.up * (ndc.y * lens.orthoHalfHeight);
    return {o, b.forward};
  }
  const float t = std::tan(glm::radians(lens.fovYDeg) * 0.5f);
  const glm::vec3 d = b.forward + b.right * (ndc.x * t * aspect) + b.up * (ndc.y * t);
  return {pose.position, glm::normalize(d)};
}

CameraPose frameBounds(const Bounds& bounds, const Lens& lens, float aspect) {
  if (bounds.empty()) return {};
  const glm::vec3 c = bounds.center(), e = bounds.extent() * 0.5f;
  // Fit the front face (x,y extent) into the view, then step back past the near half of the depth.
  const float tanY = std::tan(glm::radians(lens.fovYDeg) * 0.5f);
  const float tanX = tanY * std::max(aspect, 1e-3f);
  const float dist = std::max(e.y / tanY, e.x / tanX) * 1.05f + e.z;
  return {{c.x, c.y, c.z + std::max(dist, 1e-3f)}, 0.0f, 0.0f};
}

CameraPose orbitFrame(const Bounds& bounds, const Lens& lens, float aspect, float yawDeg, float pitchDeg) {
  if (bounds.empty()) return {};
  const glm::vec3 c = bounds.center();
  const float tanY = std::tan(glm::radians(lens.fovYDeg) * 0.5f);
  const float tanX = tanY * std::max(aspect, 1e-3f);
  const float r = std::max(glm::length(bounds.extent()) * 0.5f, 1e-3f);
  CameraPose p{{}, yawDeg, pitchDeg};
  p.position = c - basis(p).forward * (r / std::sin(std::atan(std::min(tanX, tanY))) * 1.02f);
  return p;
}

Lens fitDepthRange(Lens lens, const Bounds& bounds, const CameraPose& pose) {
  if (bounds.empty()) return lens;
  const glm::vec3 c = bounds.center();
  const float r = glm::length(bounds.extent()) * 0.5f;
  const float far = glm::length(c - pose.position) + r;
  lens.zFar = std::max(far * 1.01f, lens.zNear * 2.0f);
  lens.zNear = std::max(lens.zFar * 1e-4f, std::min(lens.zNear, lens.zFar * 0.01f));
  return lens;
}

}  // namespace rtr
