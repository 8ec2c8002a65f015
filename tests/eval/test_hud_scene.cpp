// Scene `hud` (eval/scene_hud.h): head-locked quads follow the render pose, so they keep their
// pixels in both eyes under any head motion while the world-locked picture moves; the overlay mask
// and its RMSE pick exactly the near pixels.
#include "eye_rig.h"
#include "scene.h"
#include "scene_hud.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <glm/gtc/quaternion.hpp>

namespace steadyxr::eval {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr int kWidth = 96;

// Index 0 white (as gatherTextures) and a 4:3 picture: the image viewer's plane reads its size.
TextureSet pictureTextures() {
  TextureSet t;
  Rgba8 white, picture;
  white.width = white.height = 1;
  white.pixels = {255, 255, 255, 255};
  picture.width = 4;
  picture.height = 3;
  picture.pixels.assign(4 * 3 * 4, 128);
  t.images = {white, picture};
  t.names = {"white", "picture"};
  return t;
}

Scene hudScene(double tangentScale) {
  Scene scene;
  std::string error;
  EXPECT_TRUE(makeScene("hud", "picture", pictureTextures(), tangentScale, HeadPose{}, &scene, &error))
      << error;
  return scene;
}

HeadPose turnedHead(float yawDeg, float pitchDeg, glm::vec3 position) {
  HeadPose head;
  head.orientation = glm::angleAxis(float(yawDeg * kDegToRad), glm::vec3(0, 1, 0)) *
                     glm::angleAxis(float(pitchDeg * kDegToRad), glm::vec3(1, 0, 0));
  head.position = position;
  return head;
}

// The pixel of the unit quad's `corner` of quad `q` in eye `eye`, seen from `head` at --ppd `ppd`.
glm::vec2 cornerPixel(const Scene& scene, const HeadPose& head, double ppd, size_t q, glm::vec2 corner,
                      int eye) {
  const DrawList d = scene.drawsAt(0.0, head);
  EXPECT_LT(q, d.quads.size());
  const auto cams = eyeCameras(head, kWidth, kWidth, EyeRig{ppd});
  glm::vec2 px(0.0f);
  float depth = 0;
  EXPECT_TRUE(project(cams[eye], glm::vec3(d.quads[q].model * glm::vec4(corner, 0.0f, 1.0f)), &px, &depth));
  return px;
}

TEST(EvalHudScene, HeadLockedQuadsKeepTheirPixelsWhileThePictureMoves) {
  for (const double ppd : {0.0, 20.0}) {
    const Scene scene = hudScene(ppdTangentScale(ppd, kWidth));
    ASSERT_EQ(scene.headLocked.size(), 3u);
    ASSERT_EQ(scene.drawsAt(0.0).quads.size(), 1u);  // the world-only draws: the picture alone
    // A tremor-sized turn (0.5 deg, ~0.4 px at the default density, ~10 px at 20 ppd) and a sway
    // (3 deg and 4 cm).
    const HeadPose still{}, moved[] = {turnedHead(0.5f, -0.3f, glm::vec3(0.0f)),
                                       turnedHead(3.0f, 1.0f, glm::vec3(0.04f, -0.01f, 0.02f))};
    for (const HeadPose& head : moved) {
      for (int eye = 0; eye < 2; ++eye) {
        for (const glm::vec2 corner : {glm::vec2(-0.5f), glm::vec2(0.5f), glm::vec2(-0.5f, 0.5f)}) {
          for (size_t q = 1; q <= scene.headLocked.size(); ++q) {
            const glm::vec2 a = cornerPixel(scene, still, ppd, q, corner, eye);
            const glm::vec2 b = cornerPixel(scene, head, ppd, q, corner, eye);
            EXPECT_NEAR(b.x, a.x, 1e-3) << "ppd " << ppd << " quad " << q << " eye " << eye;
            EXPECT_NEAR(b.y, a.y, 1e-3) << "ppd " << ppd << " quad " << q << " eye " << eye;
          }
          // The world-locked picture moves by the head's motion: over 0.3 px even for the tremor.
          const glm::vec2 a = cornerPixel(scene, still, ppd, 0, corner, eye);
          const glm::vec2 b = cornerPixel(scene, head, ppd, 0, corner, eye);
          EXPECT_GT(glm::length(b - a), 0.3f) << "ppd " << ppd << " eye " << eye;
        }
      }
    }
  }
}

TEST(EvalHudScene, EyesSeeTheHudAtItsHeadSpaceDistance) {
  // Disparity: the reticle's centre differs between the eyes by the IPD seen at kHudDistanceM
  // (focal px x IPD / distance), not by the picture's (at 1.5 m).
  const Scene scene = hudScene(1.0);
  const HeadPose head = turnedHead(5.0f, 2.0f, glm::vec3(0.1f, 0.0f, -0.2f));
  const glm::vec2 left = cornerPixel(scene, head, 0.0, 1, glm::vec2(0.0f), 0);
  const glm::vec2 right = cornerPixel(scene, head, 0.0, 1, glm::vec2(0.0f), 1);
  // The eyes' fovs are asymmetric (eyeFov): the same direction at infinity lands apart already.
  const auto cams = eyeCameras(head, kWidth, kWidth, EyeRig{0.0});
  glm::vec2 leftFar, rightFar;
  ASSERT_TRUE(projectDirection(cams[0], head.orientation * glm::vec3(0, 0, -1), &leftFar));
  ASSERT_TRUE(projectDirection(cams[1], head.orientation * glm::vec3(0, 0, -1), &rightFar));
  const double focalPx = centrePixelsPerDegree(eyeFov(0), kWidth) * 180.0 / std::numbers::pi;
  EXPECT_NEAR((left.x - right.x) - (leftFar.x - rightFar.x), focalPx * kIpdM / kHudDistanceM, 0.05);
  EXPECT_NEAR(left.y, right.y, 1e-3);
}

TEST(EvalHudScene, OverlayMaskIsTheNearPixelsDilatedByOne) {
  const auto cams = eyeCameras(HeadPose{}, 16, 16, EyeRig{0.0});
  DepthMap depth;
  depth.width = depth.height = 16;
  depth.depth.assign(16 * 16, 1.0f);
  auto isNear = [](int x, int y) { return x >= 5 && x <= 7 && y >= 4 && y <= 9; };
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      if (x == 15) continue;  // nothing drawn there
      // The raster depth of the point at view distance 1.0 (near) or 1.5 m along the pixel's ray.
      const glm::vec3 dir = pixelDirection(cams[0], float(x) + 0.5f, float(y) + 0.5f);
      const float dist = isNear(x, y) ? 1.0f : 1.5f;
      glm::vec2 px;
      float d = 0;
      ASSERT_TRUE(project(cams[0], cams[0].pose.position + dir * (dist / -dir.z), &px, &d));
      depth.depth[size_t(y) * 16 + x] = d;
    }
  }
  const std::vector<uint8_t> mask = overlayMask(depth, cams[0], 1.25f);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      EXPECT_EQ(mask[size_t(y) * 16 + x], (x >= 4 && x <= 8 && y >= 3 && y <= 10) ? 1 : 0) << x << "," << y;

  // RMSE over the mask alone: errors outside it do not count.
  Image a(16, 16, 0.5f), b(16, 16, 0.5f);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) a.at(x, y)[1] = mask[size_t(y) * 16 + x] ? 0.6f : 0.9f;
  EXPECT_NEAR(maskedRmse(a, b, mask), std::sqrt(0.01 / 3.0), 1e-6);
  EXPECT_EQ(maskedRmse(a, b, std::vector<uint8_t>(16 * 16, 0)), -1.0);
}

}  // namespace
}  // namespace steadyxr::eval
