// Orbit mode of the viewer's camera: drags turn about the target, scroll zooms towards it, pans move both.
#include <gtest/gtest.h>

#include "camera_controller.hpp"

namespace rtr::view {
namespace {

void expectNear(const glm::vec3& a, const glm::vec3& b, float tol = 1e-4f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

CameraController orbiting() {
  CameraController c({{1.0f, 2.0f, 10.0f}, 10.0f, -5.0f}, {});
  c.setMode(CameraMode::Orbit);
  c.setOrbitDistance(8.0f);
  c.mouseMoved(100, 100);  // the first position is the drag's origin
  return c;
}

TEST(OrbitCamera, RotateDragTurnsAboutTheTarget) {
  CameraController c = orbiting();
  const glm::vec3 target = c.orbitTarget();
  const CameraPose before = c.pose();
  c.setDrag(Drag::Rotate);
  c.mouseMoved(160, 130);
  EXPECT_LT(c.pose().yawDeg, before.yawDeg - 10.0f);  // right: the camera goes round to the left
  EXPECT_LT(c.pose().pitchDeg, before.pitchDeg - 5.0f);
  expectNear(c.orbitTarget(), target);  // still on the view axis, same distance
  EXPECT_NEAR(glm::length(c.pose().position - target), 8.0f, 1e-4f);
}

TEST(OrbitCamera, ScrollMovesTowardsTheTarget) {
  CameraController c = orbiting();
  const glm::vec3 target = c.orbitTarget();
  c.scrolled(2);
  EXPECT_NEAR(c.orbitDistance(), 8.0f * 0.81f, 1e-4f);
  expectNear(c.orbitTarget(), target);
  c.scrolled(-2);
  EXPECT_NEAR(c.orbitDistance(), 8.0f, 1e-4f);
}

TEST(OrbitCamera, PanMovesCameraAndTargetTogether) {
  CameraController c = orbiting();
  const CameraPose before = c.pose();
  const glm::vec3 target = c.orbitTarget();
  c.setDrag(Drag::Pan);
  c.mouseMoved(140, 100);
  const glm::vec3 moved = c.pose().position - before.position;
  EXPECT_GT(glm::length(moved), 0.1f);
  expectNear(c.orbitTarget() - target, moved);
  EXPECT_EQ(c.pose().yawDeg, before.yawDeg);
  EXPECT_LT(glm::dot(moved, basis(before).right), 0.0f);  // the scene follows the cursor: the camera goes left
}

TEST(OrbitCamera, DragsDoNothingInFlyModeOrWithoutAButton) {
  CameraController c = orbiting();
  c.mouseMoved(150, 150);  // no button held
  CameraPose p = c.pose();
  EXPECT_EQ(p.position, glm::vec3(1.0f, 2.0f, 10.0f));
  c.setMode(CameraMode::Fly);
  c.setDrag(Drag::Rotate);
  c.mouseMoved(250, 250);
  EXPECT_EQ(c.pose().position, p.position);
  EXPECT_EQ(c.pose().yawDeg, p.yawDeg);
}

}  // namespace
}  // namespace rtr::view
