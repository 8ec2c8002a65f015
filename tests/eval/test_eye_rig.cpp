// --ppd's fov arithmetic (eye_rig.h), checked by what it must do to pixels: a head rotation of
// one degree moves the view's centre by F pixels, and the fov's shape is kept.
#include "eye_rig.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <glm/gtc/quaternion.hpp>

namespace steadyxr::eval {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// Where a world direction lands in the left eye for a head turned by yawDeg about the vertical.
glm::vec2 pixelOfDirection(glm::vec3 dir, double yawDeg, double ppd, int w = 96, int h = 96) {
  HeadPose head;
  head.orientation = glm::angleAxis(float(yawDeg * kDegToRad), glm::vec3(0.0f, 1.0f, 0.0f));
  glm::vec2 px(0.0f);
  EXPECT_TRUE(projectDirection(eyeCameras(head, w, h, EyeRig{ppd})[0], dir, &px));
  return px;
}

TEST(EvalEyeRig, DefaultFovIsUnderOnePixelPerDegreeAt96) {
  // 96 / (tan 0.82 + tan 0.73) = 48.8 px focal length = 0.85 px per degree (s4-d's figure).
  EXPECT_NEAR(centrePixelsPerDegree(eyeFov(0), 96), 0.8517, 1e-3);
  EXPECT_NEAR(centrePixelsPerDegree(eyeFov(1), 96), 0.8517, 1e-3);
}

TEST(EvalEyeRig, PpdOffKeepsTheFovExactly) {
  const auto a = eyeCameras(HeadPose{}, 96, 96, EyeRig{0.0});
  for (int eye = 0; eye < 2; ++eye) {
    EXPECT_EQ(a[eye].fov.angleLeft, eyeFov(eye).angleLeft);
    EXPECT_EQ(a[eye].fov.angleRight, eyeFov(eye).angleRight);
    EXPECT_EQ(a[eye].fov.angleUp, eyeFov(eye).angleUp);
    EXPECT_EQ(a[eye].fov.angleDown, eyeFov(eye).angleDown);
  }
}

TEST(EvalEyeRig, OneDegreeOfYawMovesTheCentreByPpdPixels) {
  const glm::vec3 ahead(0.0f, 0.0f, -1.0f);
  for (const double ppd : {14.0, 20.0, 25.0}) {
    for (const int w : {96, 256}) {
      // A small turn (0.05 deg) so the centre's local density is what is measured.
      const glm::vec2 still = pixelOfDirection(ahead, 0.0, ppd, w, w);
      const glm::vec2 turned = pixelOfDirection(ahead, 0.05, ppd, w, w);
      EXPECT_NEAR(std::fabs(turned.x - still.x) / 0.05, ppd, 0.01 * ppd) << "ppd " << ppd << " width " << w;
      EXPECT_NEAR(turned.y, still.y, 1e-3);
    }
  }
}

TEST(EvalEyeRig, ShapeKeptCentreOnTheSamePixel) {
  // Scaling every tangent keeps the asymmetric fov's centre of projection (the pixel of the
  // straight-ahead direction) and the ratio of vertical to horizontal focal length.
  const glm::vec3 ahead(0.0f, 0.0f, -1.0f);
  const glm::vec2 wide = pixelOfDirection(ahead, 0.0, 0.0), narrow = pixelOfDirection(ahead, 0.0, 20.0);
  EXPECT_NEAR(narrow.x, wide.x, 1e-3);
  EXPECT_NEAR(narrow.y, wide.y, 1e-3);
  const auto cams = eyeCameras(HeadPose{}, 96, 96, EyeRig{20.0});
  const core::Fov f = cams[0].fov, d = eyeFov(0);
  auto span = [](float a, float b) { return std::tan(double(a)) - std::tan(double(b)); };
  EXPECT_NEAR(span(f.angleUp, f.angleDown) / span(f.angleRight, f.angleLeft),
              span(d.angleUp, d.angleDown) / span(d.angleRight, d.angleLeft), 1e-5);
  // 96 px at 20 ppd: about 4.8 degrees across.
  EXPECT_NEAR((f.angleRight - f.angleLeft) / kDegToRad, 4.8, 0.05);
}

TEST(EvalEyeRig, PictureMovedByTheInverseScaleKeepsItsPixels) {
  // The image viewer's rule (scene.cpp, picturePlane): at distance 1.5 m / tangent scale the
  // picture's corner lands on the pixel it has without --ppd, in both eyes (disparity kept).
  const double scale = ppdTangentScale(20.0, 96);
  const auto wide = eyeCameras(HeadPose{}, 96, 96, EyeRig{0.0}),
             narrow = eyeCameras(HeadPose{}, 96, 96, EyeRig{20.0});
  for (int eye = 0; eye < 2; ++eye) {
    glm::vec2 a, b;
    float wideDepth = 0, narrowDepth = 0;
    ASSERT_TRUE(project(wide[eye], glm::vec3(0.4f, 0.3f, -1.5f), &a, &wideDepth));
    ASSERT_TRUE(project(narrow[eye], glm::vec3(0.4f, 0.3f, float(-1.5 / scale)), &b, &narrowDepth));
    EXPECT_NEAR(b.x, a.x, 2e-3);
    EXPECT_NEAR(b.y, a.y, 2e-3);
    // In front of the ground truth's background quad at raster depth 0.999 (renderer.cpp), as
    // without --ppd: the near plane moved out with the picture.
    EXPECT_LT(wideDepth, 0.999f);
    EXPECT_LT(narrowDepth, 0.999f);
  }
}

// --cant: a headset with canted displays turns each eye's view outwards about the vertical. So the direction
// that is straight ahead of the head lands in the left eye where, without the cant, a direction that far to
// the right lands (and mirrored in the right eye), and a direction turned outwards by the cant lands where
// straight ahead did; the eyes stay where they were, and nothing moves vertically.
TEST(EvalEyeRig, CantTurnsEachEyeOutwards) {
  const double cantDeg = 10.0;
  const auto yawed = [](double deg) {  // a positive yaw turns -Z towards -X: to the left
    return glm::vec3(float(-std::sin(deg * kDegToRad)), 0.0f, float(-std::cos(deg * kDegToRad)));
  };
  const auto parallel = eyeCameras(HeadPose{}, 96, 96, EyeRig{}),
             canted = eyeCameras(HeadPose{}, 96, 96, EyeRig{0.0, cantDeg});
  for (int eye = 0; eye < 2; ++eye) {
    const double outwards = eye == 0 ? cantDeg : -cantDeg;
    glm::vec2 aheadCanted, inwardsParallel, outwardsCanted, aheadParallel;
    ASSERT_TRUE(projectDirection(canted[eye], yawed(0.0), &aheadCanted));
    ASSERT_TRUE(projectDirection(parallel[eye], yawed(-outwards), &inwardsParallel));
    ASSERT_TRUE(projectDirection(canted[eye], yawed(outwards), &outwardsCanted));
    ASSERT_TRUE(projectDirection(parallel[eye], yawed(0.0), &aheadParallel));
    EXPECT_NEAR(aheadCanted.x, inwardsParallel.x, 1e-3) << "eye " << eye;
    EXPECT_NEAR(aheadCanted.y, inwardsParallel.y, 1e-3) << "eye " << eye;
    EXPECT_NEAR(outwardsCanted.x, aheadParallel.x, 1e-3) << "eye " << eye;
    EXPECT_NEAR(outwardsCanted.y, aheadParallel.y, 1e-3) << "eye " << eye;
    // Straight ahead moves towards the nose: right in the left eye's image, left in the right eye's.
    EXPECT_GT((aheadCanted.x - aheadParallel.x) * (eye == 0 ? 1.0f : -1.0f), 5.0f) << "eye " << eye;
    EXPECT_EQ(canted[eye].pose.position, parallel[eye].pose.position);
  }
}

// --cant with --ppd: each eye's crop is the part of its canted view around the head's straight ahead, so that
// straight ahead lands on the pixel it has in the parallel eye's crop at the same density, in both eyes.
// There the canted view's tangent plane is 1/cos^2(cant) denser than at its axis: a small head turn moves it
// by ppd / cos^2(cant) pixels a degree.
TEST(EvalEyeRig, CantedCropsAtAPixelDensityLookStraightAhead) {
  const glm::vec3 ahead(0.0f, 0.0f, -1.0f);
  for (const double cantDeg : {10.0, 15.0}) {
    for (const double ppd : {14.0, 20.0}) {
      const auto parallel = eyeCameras(HeadPose{}, 96, 96, EyeRig{ppd});
      const auto canted = eyeCameras(HeadPose{}, 96, 96, EyeRig{ppd, cantDeg});
      HeadPose turned;
      turned.orientation = glm::angleAxis(float(0.05 * kDegToRad), glm::vec3(0.0f, 1.0f, 0.0f));
      const auto cantedTurned = eyeCameras(turned, 96, 96, EyeRig{ppd, cantDeg});
      for (int eye = 0; eye < 2; ++eye) {
        glm::vec2 p, c, t;
        ASSERT_TRUE(projectDirection(parallel[eye], ahead, &p));
        ASSERT_TRUE(projectDirection(canted[eye], ahead, &c));
        ASSERT_TRUE(projectDirection(cantedTurned[eye], ahead, &t));
        EXPECT_NEAR(c.x, p.x, 1e-2) << "cant " << cantDeg << " ppd " << ppd << " eye " << eye;
        EXPECT_NEAR(c.y, p.y, 1e-2) << "cant " << cantDeg << " ppd " << ppd << " eye " << eye;
        const double cosCant = std::cos(cantDeg * kDegToRad);
        EXPECT_NEAR(std::fabs(t.x - c.x) / 0.05, ppd / (cosCant * cosCant), 0.01 * ppd)
            << "cant " << cantDeg << " ppd " << ppd << " eye " << eye;
      }
    }
  }
}

}  // namespace
}  // namespace steadyxr::eval
