#include "camera_controller.hpp"

#include <algorithm>

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

void CameraController::mouseMoved(double x, double y) {
  if (mouseLook_ && !firstMouse_) {
    pose_.yawDeg -= float(x - lastX_) * speeds_.degreesPerPixel;
    pose_.pitchDeg = std::clamp(pose_.pitchDeg - float(y - lastY_) * speeds_.degreesPerPixel, -89.0f, 89.0f);
  }
  firstMouse_ = false;
  lastX_ = x;
  lastY_ = y;
}

}  // namespace rtr::view
