#include "camera_controller.hpp"

#include <algorithm>
#include <cmath>

namespace rtr::view {

float CameraController::speed() const {
  float s = speeds_.base;
  if (keys_[size_t(Move::Fast)]) s *= speeds_.fastFactor;
  if (keys_[size_t(Move::Slow)]) s *= speeds_.slowFactor;
  return s;
}

void CameraController::update(float seconds) {
  const CameraBasis b = basis(pose_);
  auto held = [&](Move m) { return keys_[size_t(m)] ? 1.0f : 0.0f; };
  // Relative to the view: forward follows the look direction, up the camera's up.
  glm::vec3 dir = b.forward * (held(Move::Forward) - held(Move::Back)) + b.right * (held(Move::Right) - held(Move::Left)) +
                  b.up * (held(Move::Up) - held(Move::Down));
  pose_.position += dir * (speed() * seconds);
}

glm::vec3 CameraController::orbitTarget() const { return pose_.position + basis(pose_).forward * distance_; }

void CameraController::scrolled(double steps) {
  const glm::vec3 target = orbitTarget();
  distance_ = std::max(1e-6f, distance_ * std::pow(0.9f, float(steps)));
  pose_.position = target - basis(pose_).forward * distance_;
}

void CameraController::mouseMoved(double x, double y) {
  const float dx = float(x - lastX_), dy = float(y - lastY_);
  if (mouseLook_ && !firstMouse_) {
    pose_.yawDeg -= dx * speeds_.degreesPerPixel;
    pose_.pitchDeg = std::clamp(pose_.pitchDeg - dy * speeds_.degreesPerPixel, -89.0f, 89.0f);
  } else if (mode_ == CameraMode::Orbit && drag_ == Drag::Rotate) {
    // Dragging right/down turns the scene with the cursor: the camera goes left/up around the target.
    const glm::vec3 target = orbitTarget();
    pose_.yawDeg -= dx * speeds_.degreesPerPixel;
    pose_.pitchDeg = std::clamp(pose_.pitchDeg - dy * speeds_.degreesPerPixel, -89.0f, 89.0f);
    pose_.position = target - basis(pose_).forward * distance_;
  } else if (mode_ == CameraMode::Orbit && drag_ == Drag::Pan) {
    // 0.0015 x the target distance per pixel: the cursor's own speed on the target plane in a 720-pixel-high
    // view at a 60 degree field of view.
    const CameraBasis b = basis(pose_);
    pose_.position += (-b.right * dx + b.up * dy) * (distance_ * 0.0015f);
  }
  firstMouse_ = false;
  lastX_ = x;
  lastY_ = y;
}

}  // namespace rtr::view
