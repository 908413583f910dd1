// Fuzzes the camera pose strings ("x,y,z,yaw,pitch"; a light position is "x,y,z" read the same way with
// ",0,0" appended): a pose, or an error; a parsed pose is finite and round-trips through formatPose.
#include <cmath>
#include <cstdint>
#include <string>

#include "check.hpp"
#include "core/camera.hpp"

namespace {

void check(const std::string& text) {
  using rtr::fuzz::require;
  rtr::CameraPose p;
  try {
    p = rtr::parsePose(text);
  } catch (const rtr::Error&) { return; }
  const float v[] = {p.position.x, p.position.y, p.position.z, p.yawDeg, p.pitchDeg};
  for (float f : v) require(std::isfinite(f), "a parsed pose is not finite");
  const rtr::CameraPose q = rtr::parsePose(rtr::formatPose(p));
  require(q.position == p.position && q.yawDeg == p.yawDeg && q.pitchDeg == p.pitchDeg, "formatPose does not round-trip");
  const rtr::CameraBasis b = rtr::basis(p);
  for (int i = 0; i < 3; ++i) require(std::isfinite(b.forward[i]) && std::isfinite(b.up[i]), "camera basis not finite");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  check(text);
  check(text + ",0,0");
  return 0;
}
