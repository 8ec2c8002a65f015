// Params::steadyClipCurvature on real Vulkan: a slowly moving smooth picture is followed (its lag
// is first order, the box second order), a static aliased picture under sub-pixel head tremor
// keeps its accumulation (its second differences are large, the box stays gamma sigma).
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/quaternion.hpp>
#include <optional>
#include <random>

#include "filter_test_rig.h"
#include "reference.h"

using namespace steadyxr;
using namespace steadyxr::core;
using namespace steadyxr::test;

namespace {

constexpr float kPi = 3.14159265358979f;

// The curvature box on or off; `centred`: round 7's one-sided box or round 6's symmetric one;
// `gated`: round 10's option (off by default), the one-sided box only where the history lags on one side.
Params steadyWithCurvatureBox(bool on, bool centred = false, bool gated = false) {
  Params p = *applyMethodName("steady");
  p.steadyNoiseEstimate = false;     // the box alone (round 15's default widens it by the render's noise,
  p.steadyGainCompensation = false;  // round 16's undoes a fade before the box sees it)
  p.steadyClipCurvature = on;
  p.steadyClipCurvatureCentred = centred;
  p.steadyClipCurvatureCentredGated = gated;
  return p;
}

// A smooth picture whose x profile slides right by `shiftPx`: a sinusoid of period 24 px along x
// (smooth over a pixel: its second difference is (2 pi / 24)^2 = 0.07 of its amplitude), times a
// gentle vertical variation. Point samples at pixel centres; channels differ.
glm::vec3 smoothPicture(float x, float y, float shiftPx) {
  const float s = std::sin(2.0f * kPi * (x - shiftPx) / 24.0f);
  const float v = 0.85f + 0.15f * std::cos(2.0f * kPi * y / 40.0f);
  return glm::vec3(0.5f + 0.35f * s * v, 0.45f + 0.3f * s, 0.5f - 0.25f * s * v);
}

// The output's displacement along x against the picture it should show (px, positive: the output
// shows the picture as it was further left, i.e. it lags the rightward motion): out(x) =
// truth(x + lag) = truth + lag * d truth / dx, least squares over the interior, all channels.
double lagPx(const HostImage& out, float shiftPx, uint32_t W, uint32_t H) {
  double num = 0.0, den = 0.0;
  for (uint32_t y = 3; y + 3 < H; ++y)
    for (uint32_t x = 3; x + 3 < W; ++x) {
      const float px = float(x) + 0.5f, py = float(y) + 0.5f;
      const glm::vec3 truth = smoothPicture(px, py, shiftPx);
      const glm::vec3 slope =
          (smoothPicture(px + 0.01f, py, shiftPx) - smoothPicture(px - 0.01f, py, shiftPx)) / 0.02f;
      const glm::vec3 err = glm::vec3(out.at(x, y)) - truth;
      num += glm::dot(err, slope);
      den += glm::dot(slope, slope);
    }
  return num / den;
}

// Head still, the picture sliding 0.3 px a frame (a slowly moving object at a VR app rate, the
// regime of s6-b's miss): the mean lag over the last 16 of 48 frames.
std::optional<double> steadyLagOnSlidingPicture(bool curvatureBox) {
  const uint32_t W = 48, H = 32;
  auto f = makeFilter("steady", steadyWithCurvatureBox(curvatureBox));
  if (!f) return std::nullopt;
  Rig rig(W, H);
  double lag = 0.0;
  for (int k = 0; k < 48; ++k) {
    const float shift = 0.3f * float(k);
    HostImage img(W, H);
    for (uint32_t y = 0; y < H; ++y)
      for (uint32_t x = 0; x < W; ++x)
        img.at(x, y) = glm::vec4(smoothPicture(x + 0.5f, y + 0.5f, shift), 1.0f);
    const auto out = rig.run(*f, Frame{{img, img}, {eye(0, 0), eye(0, 0)}}, 1);
    if (k >= 32) lag += lagPx(out[0], shift, W, H) / 16.0;
  }
  return lag;
}

// An aliased picture at infinity: a checkerboard of 0.7 px cells (above the Nyquist limit),
// indexed by the ray's azimuth and elevation in units of a centre pixel.
float checker(glm::vec3 worldDir, uint32_t W) {
  const float pxPerRad = float(W) / 2.0f;  // Fov{} (+-45 deg): tan x = 2 x / W - 1
  const float u = std::atan2(worldDir.x, -worldDir.z) * pxPerRad;
  const float v = std::asin(glm::clamp(worldDir.y, -1.0f, 1.0f)) * pxPerRad;
  const bool odd = (int(std::floor(u / 0.7f)) + int(std::floor(v / 0.7f))) & 1;
  return odd ? 0.85f : 0.15f;
}

// The picture a view sees: each pixel the mean of sub x sub point samples over its area (sub = 1:
// its centre, the render; sub = 8: the pixel-area average, the ground truth).
HostImage renderChecker(const RefView& view, uint32_t W, uint32_t H, int sub) {
  // The checkerboard seen through pixel position (px, py): its ray turned into the world.
  auto seen = [&](float px, float py) {
    const glm::vec3 eyeDir(2.0f * px / float(W) - 1.0f, 1.0f - 2.0f * py / float(H), -1.0f);
    return checker(view.pose.orientation * glm::normalize(eyeDir), W);
  };
  HostImage img(W, H);
  for (uint32_t y = 0; y < H; ++y)
    for (uint32_t x = 0; x < W; ++x) {
      float sum = 0.0f;
      for (int k = 0; k < sub * sub; ++k)  // a sub x sub grid of sample positions
        sum += seen(float(x) + (float(k % sub) + 0.5f) / float(sub),
                    float(y) + (float(k / sub) + 0.5f) / float(sub));
      const float c = sum / float(sub * sub);
      img.at(x, y) = glm::vec4(c, c, c, 1.0f);
    }
  return img;
}

// Sub-pixel yaw/pitch tremor (uniform, +-0.4 px at the centre) over a static aliased checkerboard:
// RMSE against the pixel-area average over the last 16 of 40 frames, for `method` with the box
// on or off ("none": the render itself).
std::optional<double> rmseUnderTremor(const std::string& method, bool curvatureBox, bool centred = false,
                                      bool gated = false) {
  const uint32_t W = 48, H = 48;
  auto f = makeFilter(method, steadyWithCurvatureBox(curvatureBox, centred, gated));
  if (!f) return std::nullopt;
  Rig rig(W, H);
  std::mt19937 rng(7);                                    // the same tremor for every method
  const float pxDeg = std::atan(2.0f / float(W)) / kDeg;  // one centre pixel, degrees
  std::uniform_real_distribution<float> tremor(-0.4f * pxDeg, 0.4f * pxDeg);
  double sum = 0.0;
  for (int k = 0; k < 40; ++k) {
    RefView view;
    view.fov = Fov{};
    view.pose.orientation = glm::angleAxis(tremor(rng) * kDeg, glm::vec3(0, 1, 0)) *
                            glm::angleAxis(tremor(rng) * kDeg, glm::vec3(1, 0, 0));
    const HostImage img = renderChecker(view, W, H, 1);
    const auto out = rig.run(*f, Frame{{img, img}, {view, view}}, 1);
    if (k >= 24) sum += rmse(out[0], renderChecker(view, W, H, 8)) / 16.0;
  }
  return sum;
}

}  // namespace

// The default's box (mean +- 0.5 sigma) holds a history 0.3 px a frame behind a smooth picture:
// nothing is rejected and alpha stays at its floor. With the second-order bound the lag is
// clipped, the clip's t^2 lowers the sample count and the output follows.
TEST_F(CoreTest, SteadyCurvatureBoxFollowsASlowlySlidingSmoothPicture) {
  const std::optional<double> lagDefaultOrNot = steadyLagOnSlidingPicture(false);
  const std::optional<double> lagCurvatureOrNot = steadyLagOnSlidingPicture(true);
  ASSERT_TRUE(lagDefaultOrNot && lagCurvatureOrNot) << "filter creation failed";
  const double lagDefault = *lagDefaultOrNot, lagCurvature = *lagCurvatureOrNot;
  // Measured (lavapipe): 0.236 px with the default box (held inside its 0.5 sigma = 0.41 px of
  // slope), 0.012 px with the curvature box.
  EXPECT_GT(lagDefault, 0.15) << "the default box should lag here (the case this switch is for)";
  EXPECT_LT(lagCurvature, 0.5 * lagDefault) << "default " << lagDefault << " px, curvature " << lagCurvature;
}

// Aliased detail has large second differences: the box stays the default's and the accumulation
// (the point of steady on a still picture) is kept.
TEST_F(CoreTest, SteadyCurvatureBoxKeepsAccumulationOnAliasedDetail) {
  const std::optional<double> noneOrNot = rmseUnderTremor("none", false);
  const std::optional<double> steadyOrNot = rmseUnderTremor("steady", false);
  const std::optional<double> curvatureOrNot = rmseUnderTremor("steady", true);
  const std::optional<double> oneSidedOrNot = rmseUnderTremor("steady", true, true);
  ASSERT_TRUE(noneOrNot && steadyOrNot && curvatureOrNot && oneSidedOrNot) << "filter creation failed";
  const double none = *noneOrNot, steady = *steadyOrNot, curvature = *curvatureOrNot;
  EXPECT_LT(steady, 0.8 * none) << "steady should accumulate here";
  // Measured (lavapipe): none 0.286, steady 0.1531, with the curvature box 0.1533.
  EXPECT_LT(curvature, 1.05 * steady)
      << "none " << none << ", steady " << steady << ", curvature " << curvature;
  // Round 7's one-sided box (the default) pays on aliased detail, which is not smooth over three
  // samples (README item 7): measured 0.1774, 1.16x the symmetric box's 0.1533 (none 0.286). It
  // must still accumulate, and cost no more than that.
  EXPECT_LT(*oneSidedOrNot, 1.2 * curvature) << "one-sided " << *oneSidedOrNot << ", symmetric " << curvature;
}

namespace {

// Params::steadyClipCurvatureCentred: the symmetric curvature box, or the one-sided one (`gated`:
// only where the history lags on one side).
Params steadyWithCentredBox(bool centred, bool gated = false) {
  return steadyWithCurvatureBox(true, centred, gated);
}

// A fade (eval scene "fade") under a still head: the smooth picture of period `periodPx` times a
// light that ramps from 1 to 0.3 over frames 16..40. RMSE against the pixel-area average (8 x 8
// samples) over the ramp's frames, for `method` ("none": the render itself).
std::optional<double> rmseDuringFade(const std::string& method, bool centred, float periodPx,
                                     bool gated = false) {
  const uint32_t W = 48, H = 32;
  auto f = makeFilter(method, steadyWithCentredBox(centred, gated));
  if (!f) return std::nullopt;
  Rig rig(W, H);
  auto picture = [periodPx](float x, float y) {
    return smoothPicture(x * 24.0f / periodPx, y, 0.0f);  // the sinusoid's period set to periodPx
  };
  double sum = 0.0;
  for (int k = 0; k < 40; ++k) {
    const float light = k < 16 ? 1.0f : 1.0f - 0.7f * float(k - 16) / 24.0f;
    HostImage img(W, H), truth(W, H);
    for (uint32_t y = 0; y < H; ++y)
      for (uint32_t x = 0; x < W; ++x) {
        img.at(x, y) = glm::vec4(light * picture(x + 0.5f, y + 0.5f), 1.0f);
        glm::vec3 area(0.0f);
        for (int s = 0; s < 64; ++s)
          area += picture(float(x) + (float(s % 8) + 0.5f) / 8.0f, float(y) + (float(s / 8) + 0.5f) / 8.0f);
        truth.at(x, y) = glm::vec4(light * area / 64.0f, 1.0f);
      }
    const auto out = rig.run(*f, Frame{{img, img}, {eye(0, 0), eye(0, 0)}}, 1);
    if (k > 16) sum += rmse(out[0], truth) / 23.0;
  }
  return sum;
}

}  // namespace

// A fade moves every pixel's value by a little each frame: the default's symmetric box holds a
// history that lags it (too bright) on the side of the mean a static history never is; the
// one-sided box clips it and the output follows the light.
TEST_F(CoreTest, SteadyCentredCurvatureBoxFollowsAFade) {
  for (float periodPx : {4.0f, 8.0f}) {
    const std::optional<double> noneOrNot = rmseDuringFade("none", false, periodPx);
    const std::optional<double> symmetricOrNot = rmseDuringFade("steady", false, periodPx);
    const std::optional<double> centredOrNot = rmseDuringFade("steady", true, periodPx);
    ASSERT_TRUE(noneOrNot && symmetricOrNot && centredOrNot) << "filter creation failed";
    const double none = *noneOrNot, symmetric = *symmetricOrNot, centred = *centredOrNot;
    // Measured (lavapipe): period 4 px none 0.0121, symmetric 0.0254, centred 0.0084; period 8 px
    // none 0.0031, symmetric 0.0071, centred 0.0021.
    EXPECT_GT(symmetric, 1.5 * none) << "the default's box should lag here (the case this switch is for)";
    EXPECT_LT(centred, none) << "period " << periodPx << ": none " << none << ", symmetric " << symmetric
                             << ", centred " << centred;
  }
}

// Round 10 (an option, off by default; docs/method-history.md): the one-sided box only where the
// history's luma lies on the same side of the current estimate as last frame. Under tremor over
// aliased detail the side flips with where the samples land, and those frames get the symmetric box.
TEST_F(CoreTest, SteadyGatedBoxKeepsMostAccumulationOnAliasedDetail) {
  const std::optional<double> symmetricOrNot = rmseUnderTremor("steady", true, false);
  const std::optional<double> oneSidedOrNot = rmseUnderTremor("steady", true, true);
  const std::optional<double> gatedOrNot = rmseUnderTremor("steady", true, true, true);
  ASSERT_TRUE(symmetricOrNot && oneSidedOrNot && gatedOrNot) << "filter creation failed";
  const double symmetric = *symmetricOrNot, oneSided = *oneSidedOrNot, gated = *gatedOrNot;
  // Measured (lavapipe): symmetric 0.1533, one-sided 0.1774, gated 0.1731: a sixth of the gap back on
  // this full-contrast checkerboard (on the corpus about five sixths). At least a tenth.
  EXPECT_LT(gated, oneSided - 0.1 * (oneSided - symmetric))
      << "symmetric " << symmetric << ", one-sided " << oneSided << ", gated " << gated;
}

// ... and a fade, whose history lags on one side every frame, still gets the one-sided box.
TEST_F(CoreTest, SteadyGatedBoxFollowsAFade) {
  for (float periodPx : {4.0f, 8.0f}) {
    const std::optional<double> noneOrNot = rmseDuringFade("none", false, periodPx);
    const std::optional<double> gatedOrNot = rmseDuringFade("steady", true, periodPx, true);
    ASSERT_TRUE(noneOrNot && gatedOrNot) << "filter creation failed";
    // Measured (lavapipe): period 4 px none 0.0121, gated 0.0092; period 8 px none 0.0031, gated 0.0023
    // (the one-sided box everywhere: 0.0084 and 0.0021; the symmetric box 0.0254 and 0.0071).
    EXPECT_LT(*gatedOrNot, *noneOrNot)
        << "period " << periodPx << ": none " << *noneOrNot << ", gated " << *gatedOrNot;
  }
}
