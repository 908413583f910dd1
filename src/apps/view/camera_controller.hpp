#pragma once
// First-person camera motion (brief 1.3, FORMATS.md §3). Key state comes from press/release events
// (GLFW callbacks), never from polling; motion is scaled by the frame time so speed does not depend on
// the frame rate.
#include <array>

#include "core/camera.hpp"

namespace rtr::view {

enum class Move { Forward, Back, Left, Right, Up, Down, Fast, Slow, Count };

struct CameraSpeeds {
  float base = 1.7f;             // units per second
  float fastFactor = 5.0f;       // Shift
  float slowFactor = 0.05f;      // Ctrl
  float degreesPerPixel = 0.5729578f;  // 0.01 rad per pixel of mouse motion
};

class CameraController {
 public:
  CameraController(CameraPose pose, CameraSpeeds speeds) : pose_(pose), speeds_(speeds) {}

  void setKey(Move m, bool down) { keys_[size_t(m)] = down; }
  void toggleMouseLook() { mouseLook_ = !mouseLook_; firstMouse_ = true; }
  bool mouseLook() const { return mouseLook_; }
  void mouseMoved(double x, double y);  // cursor position in pixels
  void update(float seconds);           // applies held keys for `seconds` of motion

  const CameraPose& pose() const { return pose_; }
  void setPose(const CameraPose& p) { pose_ = p; }
  float speed() const;  // current units per second, with Shift/Ctrl applied

 private:
  CameraPose pose_;
  CameraSpeeds speeds_;
  std::array<bool, size_t(Move::Count)> keys_{};
  bool mouseLook_ = false, firstMouse_ = true;
  double lastX_ = 0, lastY_ = 0;
};

}  // namespace rtr::view
