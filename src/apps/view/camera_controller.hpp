#pragma once
// Camera motion (the course's task 1.3, docs/formats.md). Fly: first-person keys and mouse-look. Orbit (model viewers):
// left-drag turns the camera about a target on its view axis, scroll moves it to and from the target,
// middle-drag pans both. Key state comes from press/release events (GLFW callbacks), never from polling;
// motion is scaled by the frame time so speed does not depend on the frame rate.
#include <array>

#include "core/camera.hpp"

namespace rtr::view {

enum class Move { Forward, Back, Left, Right, Up, Down, Fast, Slow, Count };
enum class CameraMode { Fly, Orbit };
enum class Drag { None, Rotate, Pan };

struct CameraSpeeds {
  float base = 1.7f;                   // units per second
  float fastFactor = 5.0f;             // Shift
  float slowFactor = 0.05f;            // Ctrl
  float degreesPerPixel = 0.5729578f;  // 0.01 rad per pixel of mouse motion
};

class CameraController {
 public:
  CameraController(CameraPose pose, CameraSpeeds speeds) : pose_(pose), speeds_(speeds) {}

  void setKey(Move m, bool down) { keys_[size_t(m)] = down; }
  void toggleMouseLook() {
    mouseLook_ = !mouseLook_;
    firstMouse_ = true;
  }
  bool mouseLook() const { return mouseLook_; }
  void mouseMoved(double x, double y);  // cursor position in pixels
  void update(float seconds);           // applies held keys for `seconds` of motion

  // Orbit: the target lies `distance` along the view direction; keys move camera and target together.
  CameraMode mode() const { return mode_; }
  void setMode(CameraMode m) {
    mode_ = m;
    drag_ = Drag::None;
  }
  void setDrag(Drag d) { drag_ = d; }  // mouse button held (orbit mode only)
  void scrolled(double steps);         // + towards the target
  float orbitDistance() const { return distance_; }
  void setOrbitDistance(float d) { distance_ = d > 1e-6f ? d : 1e-6f; }
  glm::vec3 orbitTarget() const;

  const CameraPose& pose() const { return pose_; }
  void setPose(const CameraPose& p) { pose_ = p; }
  float speed() const;  // current units per second, with Shift/Ctrl applied
  CameraSpeeds& speeds() { return speeds_; }

 private:
  CameraPose pose_;
  CameraSpeeds speeds_;
  std::array<bool, size_t(Move::Count)> keys_{};
  bool mouseLook_ = false, firstMouse_ = true;
  double lastX_ = 0, lastY_ = 0;
  CameraMode mode_ = CameraMode::Fly;
  Drag drag_ = Drag::None;
  float distance_ = 1.0f;
};

}  // namespace rtr::view
