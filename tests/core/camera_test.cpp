#include "core/camera.hpp"

#include <algorithm>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "core/error.hpp"

namespace rtr {
namespace {

TEST(Camera, PoseRoundTripsThroughText) {
  CameraPose p{{1.5f, -2.25f, 1e-3f}, 33.0f, -12.5f};
  CameraPose q = parsePose(formatPose(p));
  EXPECT_EQ(p.position, q.position);
  EXPECT_EQ(p.yawDeg, q.yawDeg);
  EXPECT_EQ(p.pitchDeg, q.pitchDeg);
}

TEST(Camera, BadPoseTextIsAClearError) {
  EXPECT_THROW(parsePose("1,2,3,4"), Error);
  EXPECT_THROW(parsePose("1,2,x,4,5"), Error);
  EXPECT_THROW(parsePose("1,2,3,4,5,6"), Error);
  EXPECT_THROW(parsePose("1,2,3,nan,5"), Error);
  try {
    parsePose("1,2,x,4,5");
  } catch (const Error& e) { EXPECT_NE(std::string(e.what()).find("field 3"), std::string::npos) << e.what(); }
}

TEST(Camera, ZeroPoseLooksDownNegativeZ) {
  CameraBasis b = basis({});
  EXPECT_NEAR(b.forward.z, -1.0f, 1e-6f);
  EXPECT_NEAR(b.right.x, 1.0f, 1e-6f);
  EXPECT_NEAR(b.up.y, 1.0f, 1e-6f);
}

// The ray through a pixel centre must project back onto that pixel centre: raster and ray tracer agree.
TEST(Camera, RayAndProjectionAgree) {
  for (bool ortho : {false, true}) {
    CameraPose pose{{0.3f, 1.2f, 4.0f}, 25.0f, -10.0f};
    Lens lens;
    lens.orthographic = ortho;
    const float aspect = 16.0f / 9.0f;
    glm::mat4 vp = projectionMatrix(lens, aspect) * viewMatrix(pose);
    for (float px : {0.5f, 100.5f, 1919.5f}) {
      for (float py : {0.5f, 540.5f, 1079.5f}) {
        glm::vec2 ndc = pixelToNdc(px, py, 1920, 1080);
        CameraRay r = cameraRay(pose, lens, aspect, ndc);
        glm::vec4 clip = vp * glm::vec4(r.origin + r.direction * 7.0f, 1.0f);
        float fx = (clip.x / clip.w * 0.5f + 0.5f) * 1920.0f;  // Vulkan: +y clip is down the image
        float fy = (clip.y / clip.w * 0.5f + 0.5f) * 1080.0f;
        EXPECT_NEAR(fx, px, 2e-3f) << "ortho=" << ortho;
        EXPECT_NEAR(fy, py, 2e-3f) << "ortho=" << ortho;
      }
    }
  }
}

TEST(Camera, FrameBoundsSeesEveryCorner) {
  Bounds b;
  b.extend({-3, -1, -8});
  b.extend({5, 4, -2});
  Lens lens;
  CameraPose pose = frameBounds(b, lens, 1.5f);
  lens = fitDepthRange(lens, b, pose);
  glm::mat4 vp = projectionMatrix(lens, 1.5f) * viewMatrix(pose);
  for (int i = 0; i < 8; ++i) {
    glm::vec3 c{i & 1 ? b.max.x : b.min.x, i & 2 ? b.max.y : b.min.y, i & 4 ? b.max.z : b.min.z};
    glm::vec4 clip = vp * glm::vec4(c, 1.0f);
    ASSERT_GT(clip.w, 0.0f);
    EXPECT_LE(std::abs(clip.x / clip.w), 1.0f);
    EXPECT_LE(std::abs(clip.y / clip.w), 1.0f);
    EXPECT_GE(clip.z / clip.w, 0.0f);
    EXPECT_LE(clip.z / clip.w, 1.0f);
  }
}

// A bare model's three-quarter view: from the front right and above, every corner in view, far from the
// origin too.
TEST(Camera, ThreeQuarterFramingSeesEveryCornerFromAbove) {
  for (const glm::vec3 offset : {glm::vec3(0.0f), glm::vec3(1e4f, -3e3f, 2e4f)}) {
    Bounds b;
    b.extend(offset + glm::vec3(-3, -1, -8));
    b.extend(offset + glm::vec3(5, 4, -2));
    for (float aspect : {0.5f, 1.0f, 2.0f}) {
      Lens lens;
      const CameraPose pose = orbitFrame(b, lens, aspect, 35.0f, -25.0f);
      const glm::vec3 c = b.center();
      EXPECT_GT(pose.position.x, c.x);
      EXPECT_GT(pose.position.y, b.max.y);
      EXPECT_GT(pose.position.z, b.max.z);
      // It looks at the centre.
      const glm::vec3 toCentre = glm::normalize(c - pose.position);
      EXPECT_GT(glm::dot(toCentre, basis(pose).forward), 0.9999f);
      lens = fitDepthRange(lens, b, pose);
      const glm::mat4 vp = projectionMatrix(lens, aspect) * viewMatrix(pose);
      float widest = 0.0f;
      for (int i = 0; i < 8; ++i) {
        const glm::vec3 k{i & 1 ? b.max.x : b.min.x, i & 2 ? b.max.y : b.min.y, i & 4 ? b.max.z : b.min.z};
        const glm::vec4 clip = vp * glm::vec4(k, 1.0f);
        ASSERT_GT(clip.w, 0.0f);
        EXPECT_LE(std::abs(clip.x / clip.w), 1.0f) << aspect;
        EXPECT_LE(std::abs(clip.y / clip.w), 1.0f) << aspect;
        widest = std::max({widest, std::abs(clip.x / clip.w), std::abs(clip.y / clip.w)});
      }
      EXPECT_GT(widest, 0.4f) << "the model fills a fair part of the view";
    }
  }
}

}  // namespace
}  // namespace rtr
