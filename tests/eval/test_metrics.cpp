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

namespace steadyxr::eval {
namespace {

// One row of n pixels, every pixel black but pixel `lit`, which has colour (r, g, 0).
Image rowImage(int n, int lit, float r, float g) {
  Image img(n, 1, 0.0f);
  if (lit >= 0) {
    img.at(lit, 0)[0] = r;
    img.at(lit, 0)[1] = g;
  }
  return img;
}

TEST(EvalTemporalError, PerfectSequenceScoresZero) {
  const Image g0 = pattern(16, 8), g1 = pattern(16, 8, 1);
  EXPECT_DOUBLE_EQ(temporalErrorVsTruth(g0, g1, g0, g1), 0.0);
}

TEST(EvalTemporalError, LaggingSequenceHasZeroMtcdButTemporalError) {
  // The truth changes one of 4 pixels by (0.3, 0.4, 0) (norm 0.5); the output stays put, as a
  // method locked to the screen would: MTCD 0, temporal error 0.5 / 4.
  const Image g0 = rowImage(4, -1, 0, 0), g1 = rowImage(4, 2, 0.3f, 0.4f);
  const Image o = rowImage(4, 1, 0.2f, 0.2f);
  EXPECT_DOUBLE_EQ(temporalColorDifference(o, o), 0.0);
  EXPECT_NEAR(temporalErrorVsTruth(o, o, g0, g1), 0.125, 1e-6);
}

TEST(EvalTemporalError, ShimmerOverStillTruthEqualsMtcd) {
  const Image g = rowImage(4, 0, 0.5f, 0.5f);
  const Image o0 = rowImage(4, 3, 0.0f, 0.0f), o1 = rowImage(4, 3, 0.6f, 0.8f);  // one pixel flickers by 1.0
  EXPECT_NEAR(temporalErrorVsTruth(o0, o1, g, g), 0.25, 1e-6);
  EXPECT_NEAR(temporalErrorVsTruth(o0, o1, g, g), temporalColorDifference(o0, o1), 1e-12);
}

TEST(EvalTemporalError, RoundedTruthFlipsALevelWhereTheTruthCrossesABoundary) {
  // Two pixels whose truth rises by 0.2 of an 8-bit level: pixel 0 from 100.4 to 100.6 crosses
  // the rounding boundary at 100.5, so its rounded value jumps a whole level (error 1 - 0.2);
  // pixel 1 from 100.1 to 100.3 stays on level 100 (error 0.2, the change it misses). Mean over
  // the two pixels, one channel each: (0.8 + 0.2) / 2 levels.
  Image g0(2, 1), g1(2, 1);
  g0.at(0, 0)[0] = 100.4f / 255.0f;
  g1.at(0, 0)[0] = 100.6f / 255.0f;
  g0.at(1, 0)[0] = 100.1f / 255.0f;
  g1.at(1, 0)[0] = 100.3f / 255.0f;
  const Image q0 = roundTo8Bit(g0), q1 = roundTo8Bit(g1);
  EXPECT_FLOAT_EQ(q0.at(0, 0)[0] * 255.0f, 100.0f);
  EXPECT_FLOAT_EQ(q1.at(0, 0)[0] * 255.0f, 101.0f);
  EXPECT_FLOAT_EQ(q1.at(1, 0)[0] * 255.0f, 100.0f);
  EXPECT_NEAR(255.0 * temporalErrorVsTruth(q0, q1, g0, g1), 0.5, 1e-4);
  // Out-of-range values clamp to the ends, as a UNORM target stores them.
  Image wide(1, 1);
  wide.at(0, 0)[0] = -0.2f;
  wide.at(0, 0)[1] = 1.3f;
  EXPECT_FLOAT_EQ(roundTo8Bit(wide).at(0, 0)[0], 0.0f);
  EXPECT_FLOAT_EQ(roundTo8Bit(wide).at(0, 0)[1], 1.0f);
}

struct StereoRig {
  static constexpr int kSize = 32;
  EyeCamera left, right;
  DepthMap leftDepth, rightDepth;
  StereoRig() {
    core::Pose l, r;
    l.position = glm::vec3(-0.032f, 0, 0);
    r.position = glm::vec3(0.032f, 0, 0);
    left = makeEyeCamera(l, core::Fov{}, kSize, kSize);
    right = makeEyeCamera(r, core::Fov{}, kSize, kSize);
    glm::vec2 px;
    float d = 0;
    project(left, glm::vec3(0, 0, -2.0f), &px, &d);
    leftDepth = {kSize, kSize, std::vector<float>(size_t(kSize) * kSize, d)};
    rightDepth = leftDepth;
  }
};

// resampled (the render-size study shows each frame at the full size, as a compositor): the same field of
// view at another size. At its own size an image comes back to the bit; a picture linear in the horizontal
// view coordinate u (pixel centres at (x + 0.5) / width) comes back as the same function of u at the new
// size, away from the border half-pixel where bilinear clamps.
TEST(EvalTemporalError, ResampledKeepsTheFieldOfView) {
  Image noisy(23, 17);
  for (size_t i = 0; i < noisy.rgb.size(); ++i) noisy.rgb[i] = float((i * 7919) % 251) / 251.0f;
  const Image same = resampled(noisy, 23, 17);
  ASSERT_EQ(same.rgb.size(), noisy.rgb.size());
  for (size_t i = 0; i < noisy.rgb.size(); ++i) ASSERT_EQ(same.rgb[i], noisy.rgb[i]) << i;

  const int from = 40, to = 32;
  Image ramp(from, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < from; ++x)
      for (int c = 0; c < 3; ++c) ramp.at(x, y)[c] = (float(x) + 0.5f) / float(from);
  for (int size : {to, 48}) {
    const Image r = resampled(ramp, size, 4);
    ASSERT_EQ(r.width, size);
    for (int x = 0; x < size; ++x) {
      const float u = (float(x) + 0.5f) / float(size);
      if (u * float(from) < 1.0f || u * float(from) > float(from) - 1.0f) continue;  // the clamped border
      EXPECT_NEAR(r.at(x, 2)[1], u, 1e-5f) << "size " << size << " x " << x;
    }
  }
}

TEST(EvalStereoError, MatchingEyeDifferenceScoresZero) {
  // A flat plane; the truth's eyes differ (right darker); a method whose eyes differ the same way
  // scores 0 even when both eyes carry the same offset from the truth.
  const StereoRig rig;
  const Image lt(StereoRig::kSize, StereoRig::kSize, 0.5f), rt(StereoRig::kSize, StereoRig::kSize, 0.4f);
  const Image lo(StereoRig::kSize, StereoRig::kSize, 0.6f), ro(StereoRig::kSize, StereoRig::kSize, 0.5f);
  EXPECT_NEAR(stereoErrorPerPixel(lt, rt, lt, rt, rig.leftDepth, rig.left, rig.rightDepth, rig.right), 0.0,
              1e-9);
  EXPECT_NEAR(stereoErrorPerPixel(lo, ro, lt, rt, rig.leftDepth, rig.left, rig.rightDepth, rig.right), 0.0,
              1e-6);
}

TEST(EvalStereoError, PulledTogetherEyesScoreTheTruthsDifference) {
  // The truth's eyes differ by 0.1 in red; a method that makes both eyes equal is off by 0.1 at
  // every pixel both eyes see. (The image-wide "stereo gap" this replaces could not tell a
  // method that cancels errors across pixels from this one.)
  const StereoRig rig;
  const Image lt(StereoRig::kSize, StereoRig::kSize, 0.5f);
  Image rt = lt;
  for (size_t i = 0; i < rt.rgb.size(); i += 3) rt.rgb[i] = 0.4f;
  EXPECT_NEAR(stereoErrorPerPixel(lt, lt, lt, rt, rig.leftDepth, rig.left, rig.rightDepth, rig.right), 0.1,
              1e-6);
}

TEST(EvalGhosting, MotionChangesFromHeadSpeed) {
  const std::vector<double> speed = {1, 2, 1, 20, 20, 21, 1, 3};
  EXPECT_EQ(detectMotionChanges(speed, 5.0), (std::vector<int>{3, 6}));
  EXPECT_TRUE(detectMotionChanges({1, 2, 3, 4}, 5.0).empty());
}

TEST(EvalGhosting, WorstFrameAndRecovery) {
  const std::vector<double> none = {1, 1, 1, 1, 1}, method = {0.5, 3, 2, 0.9, 1.5};
  const Ghosting g = ghostingPerFrame(method, none, {1});
  EXPECT_DOUBLE_EQ(g.worstRatio, 3.0);
  EXPECT_EQ(g.worstFrame, 1);
  EXPECT_EQ(g.recoveryFrames, 2);  // frames 1 and 2 above none, frame 3 back below
  EXPECT_TRUE(g.recovered);
  const Ghosting late = ghostingPerFrame(method, none, {4});  // never back below by the end
  EXPECT_EQ(late.recoveryFrames, 1);
  EXPECT_FALSE(late.recovered);
  EXPECT_EQ(ghostingPerFrame(method, none, {3}).recoveryFrames, 0);
  EXPECT_EQ(ghostingPerFrame(none, none, {1, 2}).recoveryFrames, 0);
}

// Below the 8-bit rounding floor two errors are both "exact": their ratio is not ghosting. A real
// ghost over a frame where none is exact still counts, against the floor.
TEST(EvalGhosting, NoneBelowTheEightBitFloorCountsAsTheFloor) {
  const double floor = 1.0 / (255.0 * std::sqrt(12.0));
  const std::vector<double> none = {0.01, 5.3e-5, 5.3e-5, 0.0}, tiny = {0.005, 5.9e-5, 6e-4, 1e-4};
  const Ghosting g = ghostingPerFrame(tiny, none, {1});
  EXPECT_DOUBLE_EQ(g.worstRatio, 6e-4 / floor);
  EXPECT_EQ(g.worstFrame, 2);
  EXPECT_EQ(g.recoveryFrames, 0);  // 5.9e-5 is not "above" none's 5.3e-5 at the floor
  const std::vector<double> ghost = {0.005, 0.004, 5e-4, 0.0};
  const Ghosting gg = ghostingPerFrame(ghost, none, {1});
  EXPECT_NEAR(gg.worstRatio, 0.004 / floor, 1e-9);  // 3.5x the floor: a ghost where none is exact
  EXPECT_EQ(gg.worstFrame, 1);
  EXPECT_EQ(gg.recoveryFrames, 1);
}

TEST(EvalGhosting, PercentileIsNearestRank) {
  std::vector<double> v;
  for (int i = 100; i >= 1; --i) v.push_back(i);
  EXPECT_DOUBLE_EQ(percentile(v, 0.95), 95.0);
  EXPECT_DOUBLE_EQ(percentile(v, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(percentile(v, 1.0), 100.0);
  EXPECT_DOUBLE_EQ(percentile({}, 0.5), 0.0);
}

}  // namespace
}  // namespace steadyxr::eval

#include "steadyxr/core/jitter.h"

namespace steadyxr::eval {
namespace {

// The harness renders jittered frames through core::jitterFov, the layer's function: a point at
// pixel p of the unjittered camera must land at p - jitterPx in the jittered one, the convention
// ViewFrame::jitterPx documents and the filter un-jitters by.
TEST(EvalJitter, JitteredCameraShowsPointAtMinusJitterPx) {
  const core::Fov fov{-0.82f, 0.73f, 0.80f, -0.84f};
  const EyeCamera plain = makeEyeCamera(core::Pose{}, fov, 64, 48);
  for (uint32_t n = 0; n < core::kJitterPeriod; ++n) {
    const glm::vec2 j = core::haltonJitterPx(n);
    EXPECT_GE(j.x, -0.5f);
    EXPECT_LT(j.x, 0.5f);
    const EyeCamera jittered = makeEyeCamera(core::Pose{}, core::jitterFov(fov, j.x, j.y, 64, 48), 64, 48);
    for (const glm::vec3 p : {glm::vec3(0.3f, -0.2f, -2.0f), glm::vec3(-0.5f, 0.4f, -1.0f)}) {
      glm::vec2 a, b;
      float d = 0;
      ASSERT_TRUE(project(plain, p, &a, &d));
      ASSERT_TRUE(project(jittered, p, &b, &d));
      EXPECT_NEAR(b.x, a.x - j.x, 2e-3f);
      EXPECT_NEAR(b.y, a.y - j.y, 2e-3f);
    }
  }
  // Halton(2,3) at indices 1 and 2, centred: the layer's first two offsets.
  EXPECT_FLOAT_EQ(core::haltonJitterPx(0).x, 0.0f);
  EXPECT_NEAR(core::haltonJitterPx(0).y, 1.0f / 3.0f - 0.5f, 1e-6f);
  EXPECT_FLOAT_EQ(core::haltonJitterPx(1).x, -0.25f);
  EXPECT_EQ(core::haltonJitterPx(3), core::haltonJitterPx(3 + core::kJitterPeriod));
}

}  // namespace
}  // namespace steadyxr::eval

#include "oracle.h"
#include "pictures.h"

#include <random>

namespace steadyxr::eval {
namespace {

// A camera sliding sideways by exactly one pixel's width at a fronto-parallel plane: frame 1
// pixel x shows what frame 0 pixel x + 1 showed. Exact reprojection finds the same value in both
// frames, so the oracle returns the frame itself; a reprojection that ignored the motion would
// average neighbouring, different values.
TEST(EvalOracle, ExactReprojectionOfStaticPlaneReturnsTheScene) {
  constexpr int w = 32, h = 8;
  const float pixelM = 2.0f * 2.0f / w;  // plane at 2 m, fov +-45 deg: 4 m across w pixels
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  std::vector<float> g(w + 1);
  for (float& v : g) v = uni(rng);
  Oracle oracle(false);
  Image last;
  for (int i = 0; i < 2; ++i) {
    core::Pose pose;
    pose.position.x = i * pixelM;
    const EyeCamera cam = makeEyeCamera(pose, core::Fov{}, w, h);
    glm::vec2 px;
    float d = 0;
    ASSERT_TRUE(project(cam, glm::vec3(0, 0, -2.0f), &px, &d));
    const DepthMap depth{w, h, std::vector<float>(size_t(w) * h, d)};
    Image frame(w, h);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) frame.at(x, y)[0] = frame.at(x, y)[1] = frame.at(x, y)[2] = g[x + i];
    }
    last = oracle.step(0, frame, depth, cam, depth, cam);
    if (i == 1) {
      for (int x = 0; x < w; ++x) EXPECT_NEAR(last.at(x, 3)[0], g[x + 1], 1e-5f) << "x=" << x;
    }
  }
}

TEST(EvalOracle, StillCameraAveragesTheWindow) {
  // A still camera: every frame's own pixel is a sample; the oracle is their mean (1/N), here over
  // values 0.1, 0.2, ..., 0.5 of five frames.
  constexpr int w = 8, h = 8;
  const EyeCamera cam = makeEyeCamera(core::Pose{}, core::Fov{}, w, h);
  glm::vec2 px;
  float d = 0;
  ASSERT_TRUE(project(cam, glm::vec3(0, 0, -2.0f), &px, &d));
  const DepthMap depth{w, h, std::vector<float>(size_t(w) * h, d)};
  Oracle oracle(false);
  Image out;
  for (int i = 1; i <= 5; ++i) out = oracle.step(1, Image(w, h, 0.1f * i), depth, cam, depth, cam);
  EXPECT_NEAR(out.at(4, 4)[1], 0.3f, 1e-6f);
}

TEST(EvalPictures, ZonePlateReachesNyquistAndLinesAreOnePixel) {
  const Rgba8 zp = proceduralPicture("zoneplate", 256);
  ASSERT_GT(zp.width, 64);
  // Near the corner the local frequency is ~0.5 cycles/px: neighbours alternate strongly.
  auto v = [&](int x, int y) { return int(zp.pixels[(size_t(y) * zp.width + x) * 4]); };
  int flips = 0;
  for (int x = zp.width - 12; x < zp.width - 2; ++x)
    flips +=
        (v(x, zp.height - 1) - v(x - 1, zp.height - 1)) * (v(x + 1, zp.height - 1) - v(x, zp.height - 1)) < 0;
  EXPECT_GE(flips, 7);
  const Rgba8 lines = proceduralPicture("lines1px", 256);
  EXPECT_LT(lines.pixels[0], 64);                       // a dark line at column 0
  EXPECT_GT(lines.pixels[(1 + lines.width) * 4], 192);  // light at (1, 1)
  EXPECT_EQ(pictureClass("zoneplate"), "synthetic");
  EXPECT_EQ(pictureClass("darkgradient"), "dark");
  EXPECT_EQ(pictureClass("astronaut"), "photo");
}

TEST(EvalPictures, MipChainAveragesInLinearLight) {
  // A 2x1 texture, black and white (sRGB 0 and 255): its 1x1 level is 50 % linear grey, which is
  // sRGB code 188, not the 128 an average of the encoded values gives.
  Rgba8 img;
  img.width = 2;
  img.height = 1;
  img.pixels = {0, 0, 0, 255, 255, 255, 255, 255};
  const auto srgb = mipChain(img, true), unorm = mipChain(img, false);
  ASSERT_EQ(srgb.size(), 2u);
  EXPECT_EQ(srgb[1].width, 1);
  EXPECT_NEAR(srgb[1].pixels[0], 188, 1);
  EXPECT_NEAR(unorm[1].pixels[0], 128, 1);
  EXPECT_EQ(srgb[1].pixels[3], 255);
}

}  // namespace
}  // namespace steadyxr::eval

#include "targets.h"

namespace steadyxr::eval {
namespace {

// Two cases, one at low head speed; every method's row built so that the default meets every
// target of issue 14. Each test then breaks one figure and expects exactly that target missed.
std::vector<ResultRow> goodRows() {
  std::vector<ResultRow> rows;
  for (const char* c : {"still", "turn"}) {
    auto row = [&](const char* method, double rmse, double tempErr, double stereoErr) {
      ResultRow r;
      r.scenario = c;
      r.method = method;
      r.rmse = rmse;
      r.temporalError = tempErr;
      r.stereoError = stereoErr;
      r.ghostWorstRatio = 1.0;
      r.lowSpeed = std::string(c) == "still";
      rows.push_back(r);
    };
    row("none", 0.10, 1.0, 2.0);
    row("taa", 0.08, 0.5, 2.0);
    row("taa+jitter", 0.07, 0.5, 2.0);
    row("hybrid", 0.06, 0.3, 2.0);
    row("default", 0.06, 0.3, 1.0);
    rows.back().ghostWorstRatio = 1.05;
  }
  return rows;
}

std::vector<bool> metFlags(const std::vector<ResultRow>& rows) {
  std::vector<bool> met;
  for (const TargetCheck& t : checkTargets(rows, "hybrid")) {
    EXPECT_TRUE(t.evaluated) << t.name;
    met.push_back(t.met);
  }
  return met;
}

ResultRow& find(std::vector<ResultRow>& rows, const std::string& c, const std::string& m) {
  for (ResultRow& r : rows) {
    if (r.scenario == c && r.method == m) return r;
  }
  throw std::runtime_error("no row");
}

TEST(EvalTargets, EachTargetIsCheckedByWhatACaseIs) {
  // Order: mean RMSE <= none, worst frame <= 1.1x, recovery <= 3, shimmer, RMSE <= min(taa,
  // taa+jitter), 20 % below taa on average, stereo error 30 % below, stereo RMSE not higher,
  // shimmer at most none's.
  const std::vector<bool> all(9, true);
  EXPECT_EQ(metFlags(goodRows()), all);
  auto expectOnlyMissed = [&](std::vector<ResultRow> rows, size_t target) {
    std::vector<bool> want = all;
    want[target] = false;
    EXPECT_EQ(metFlags(rows), want) << "target " << target;
  };
  {
    auto rows = goodRows();
    find(rows, "turn", "default").ghostWorstRatio = 1.2;
    expectOnlyMissed(rows, 1);
  }
  {
    auto rows = goodRows();
    find(rows, "turn", "default").recoveryFrames = 4;
    expectOnlyMissed(rows, 2);
    find(rows, "turn", "default").recovered = false;  // 4 frames to the end and still above
    expectOnlyMissed(rows, 2);
  }
  {
    // A change 2 frames before the end, still above none there: the run ends before the 3 frames
    // the target allows, so it is neither met nor missed (listed as undecided).
    auto rows = goodRows();
    find(rows, "turn", "default").recoveryFrames = 2;
    find(rows, "turn", "default").recovered = false;
    EXPECT_EQ(metFlags(rows), all);
    bool listed = false;
    for (const TargetCheck& t : checkTargets(rows, "hybrid"))
      listed = listed || t.detail.find("1 undecided") != std::string::npos;
    EXPECT_TRUE(listed);
  }
  {
    // Shimmer counts on the low-speed case only: a high temporal error at speed is not shimmer.
    auto rows = goodRows();
    find(rows, "turn", "default").temporalError = 0.9;
    EXPECT_EQ(metFlags(rows), all);
    find(rows, "still", "default").temporalError = 0.41;
    expectOnlyMissed(rows, 3);
  }
  {
    // The promise on shimmer: above none's on a low-speed case misses it (and the 40 % target);
    // at none's it holds; a fast case above none's is not shimmer.
    auto rows = goodRows();
    find(rows, "turn", "default").temporalError = 2.0;
    find(rows, "still", "default").temporalError = 1.0;
    expectOnlyMissed(rows, 3);
    find(rows, "still", "default").temporalError = 1.01;
    std::vector<bool> want = all;
    want[3] = want[8] = false;
    EXPECT_EQ(metFlags(rows), want);
  }
  {
    auto rows = goodRows();
    find(rows, "still", "taa+jitter").rmse = 0.05;  // better than the default in one case
    expectOnlyMissed(rows, 4);
  }
  {
    auto rows = goodRows();
    find(rows, "still", "default").stereoError = 1.5;
    find(rows, "turn", "default").stereoError = 1.5;  // only 25 % below the temporal pass alone
    expectOnlyMissed(rows, 6);
  }
  {
    auto rows = goodRows();
    find(rows, "still", "default").rmse = 0.0601;  // stereo pass raised RMSE over hybrid's
    expectOnlyMissed(rows, 7);
  }
}

}  // namespace
}  // namespace steadyxr::eval
