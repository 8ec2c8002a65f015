// Metrics on constructed cases with known answers.
#include "camera.h"
#include "image.h"
#include "metrics.h"
#include "warp.h"

#include <gtest/gtest.h>

#include <cmath>

namespace steadyxr::eval {
namespace {

Image pattern(int w, int h, int shift = 0) {
  Image img(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int sx = x + shift;
      float* p = img.at(x, y);
      p[0] = float((sx * 7 + y * 3) % 17) / 16.0f;
      p[1] = float((sx / 4 + y / 4) % 2);
      p[2] = 0.5f;
    }
  }
  return img;
}

TEST(EvalMetrics, IdenticalFramesHaveZeroMtcd) {
  const Image a = pattern(32, 24);
  EXPECT_DOUBLE_EQ(temporalColorDifference(a, a), 0.0);
}

TEST(EvalMetrics, MtcdIsMeanEuclideanRgbDistance) {
  Image a(4, 4, 0.0f), b(4, 4, 0.0f);
  // Half the pixels change by (0.3, 0.4, 0): distance 0.5 -> mean 0.25.
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 4; ++x) {
      b.at(x, y)[0] = 0.3f;
      b.at(x, y)[1] = 0.4f;
    }
  }
  EXPECT_NEAR(temporalColorDifference(a, b), 0.25, 1e-6);
}

TEST(EvalMetrics, KnownShiftGivesKnownRmse) {
  // A vertical stripe pattern 0/1 alternating per column: a one-column shift flips every pixel
  // of channel 0 (error 1), channels 1, 2 are equal -> RMSE = sqrt(1/3).
  Image a(16, 8), b(16, 8);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 16; ++x) {
      a.at(x, y)[0] = float(x % 2);
      b.at(x, y)[0] = float((x + 1) % 2);
    }
  }
  EXPECT_NEAR(rmse(a, b), std::sqrt(1.0 / 3.0), 1e-6);
  EXPECT_NEAR(rmse(a, a), 0.0, 1e-12);
  Image c = a;
  for (float& v : c.rgb) v += 0.1f;  // constant offset: RMSE = offset
  EXPECT_NEAR(rmse(a, c), 0.1, 1e-6);
}

TEST(EvalMetrics, SsimOfImageWithItselfIsOne) {
  const Image a = pattern(40, 30);
  EXPECT_NEAR(ssim(a, a), 1.0, 1e-9);
  const Image b = pattern(40, 30, 3);
  EXPECT_LT(ssim(a, b), 0.9);
}

TEST(EvalMetrics, ErrorPixelsCountAboveThreshold) {
  Image a(10, 10, 0.5f), b = a;
  b.at(1, 1)[2] = 0.7f;   // above 0.1
  b.at(2, 2)[0] = 0.55f;  // below
  b.at(3, 3)[1] = 0.0f;   // above
  EXPECT_EQ(errorPixels(a, b, 0.1f), 2);
  EXPECT_EQ(errorPixels(a, a, 0.1f), 0);
}

TEST(EvalMetrics, TimewarpWithSamePoseIsIdentity) {
  core::Pose pose;
  const EyeCamera cam = makeEyeCamera(pose, core::Fov{}, 32, 32);
  const Image a = pattern(32, 32);
  const Image w = rotationalTimewarp(a, cam, cam);
  EXPECT_LT(rmse(a, w), 1e-4);
}

TEST(EvalMetrics, ProjectUnprojectRoundTrip) {
  core::Pose pose;
  pose.position = glm::vec3(0.1f, 0.2f, 0.3f);
  const EyeCamera cam = makeEyeCamera(pose, core::Fov{-0.8f, 0.7f, 0.75f, -0.85f}, 64, 48);
  const glm::vec3 p(0.4f, -0.2f, -2.0f);
  glm::vec2 px;
  float d = 0;
  ASSERT_TRUE(project(cam, p, &px, &d));
  const glm::vec3 back = unproject(cam, px.x, px.y, d);
  EXPECT_NEAR(glm::length(back - p), 0.0f, 1e-3f);
}

TEST(EvalMetrics, StereoDifferenceOfConsistentViewsIsZero) {
  // A flat, uniformly coloured plane seen by two eyes: the reprojected difference is 0.
  const int w = 32, h = 32;
  core::Pose l, r;
  l.position = glm::vec3(-0.032f, 0, 0);
  r.position = glm::vec3(0.032f, 0, 0);
  const EyeCamera cl = makeEyeCamera(l, core::Fov{}, w, h), cr = makeEyeCamera(r, core::Fov{}, w, h);
  DepthMap dl{w, h, {}}, dr{w, h, {}};
  glm::vec2 px;
  float d = 0;
  ASSERT_TRUE(project(cl, glm::vec3(0, 0, -2.0f), &px, &d));
  dl.depth.assign(size_t(w) * h, d);
  dr.depth.assign(size_t(w) * h, d);
  const Image img(w, h, 0.4f);
  const StereoDifference sd = stereoDifference(img, dl, cl, img, dr, cr);
  EXPECT_GT(sd.validFraction, 0.5);
  EXPECT_NEAR(sd.meanSquared, 0.0, 1e-9);
}

}  // namespace
}  // namespace steadyxr::eval

namespace steadyxr::eval {
namespace {

// The homography warp agrees with the per-pixel direction mapping it replaces.
TEST(EvalMetrics, TimewarpMatchesDirectionMapping) {
  core::Pose a, b;
  b.orientation = glm::angleAxis(0.05f, glm::normalize(glm::vec3(0.3f, 1.0f, 0.1f)));
  const core::Fov fov{-0.82f, 0.73f, 0.80f, -0.84f};
  const EyeCamera src = makeEyeCamera(a, fov, 40, 32), dst = makeEyeCamera(b, fov, 40, 32);
  Image img(40, 32);
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 40; ++x) img.at(x, y)[0] = float(x) / 40.0f + float(y) / 64.0f;
  }
  const Image w = rotationalTimewarp(img, src, dst);
  int checked = 0;
  for (int y = 4; y < 28; y += 5) {
    for (int x = 4; x < 36; x += 5) {
      glm::vec2 p;
      float c[3];
      if (!projectDirection(src, pixelDirection(dst, x + 0.5f, y + 0.5f), &p) ||
          !sampleBilinear(img, p.x, p.y, c)) {
        continue;
      }
      EXPECT_NEAR(w.at(x, y)[0], c[0], 1e-3f);
      ++checked;
    }
  }
  EXPECT_GT(checked, 10);
}

}  // namespace
}  // namespace steadyxr::eval
