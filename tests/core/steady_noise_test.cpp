// Params::steadyNoiseEstimate (rounds 13-15; the default since round 15) on real Vulkan: the
// render's noise is estimated from the frames as Donoho and Johnstone's robust scale of the finest
// diagonal detail, and with it steady averages per-frame noise that its clip box and blur guard let
// through.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/quaternion.hpp>
#include <optional>
#include <random>
#include <utility>
#include <vector>

#include "filter_test_rig.h"
#include "reference.h"

using namespace steadyxr;
using namespace steadyxr::core;
using namespace steadyxr::test;

namespace {

constexpr float kPi = 3.14159265358979f;

Params steadyNoiseAware(bool on, bool residualOverTime = true, bool changeTest = true) {
  Params p = *applyMethodName("steady");
  p.steadyNoiseEstimate = on;
  p.steadyNoiseResidualOverTime = residualOverTime;
  p.steadyNoiseChangeTest = changeTest;
  return p;
}

// A smooth picture at infinity, indexed by the ray's azimuth and elevation in centre pixels (a turn
// of the head moves it), its channels different and inside (0, 1) with the noise below.
glm::vec3 smoothAt(glm::vec3 worldDir, uint32_t W) {
  const float pxPerRad = float(W) / 2.0f;  // Fov{} (+-45 deg): tan x = 2 x / W - 1
  const float u = std::atan2(worldDir.x, -worldDir.z) * pxPerRad;
  const float v = std::asin(glm::clamp(worldDir.y, -1.0f, 1.0f)) * pxPerRad;
  return {0.5f + 0.2f * std::sin(2.0f * kPi * u / 20.0f), 0.45f + 0.15f * std::cos(2.0f * kPi * v / 28.0f),
          0.5f + 0.1f * std::sin(2.0f * kPi * (u + v) / 32.0f)};
}

// The view's picture: each pixel the mean of sub x sub point samples over its area, plus uniform
// noise in [-noise, noise] per channel and pixel (as the eval's noisy scenes: variance noise^2 / 3).
HostImage render(const RefView& view, uint32_t W, uint32_t H, int sub, float noise, std::mt19937& rng) {
  std::uniform_real_distribution<float> uniform(-noise, noise);
  HostImage img(W, H);
  for (uint32_t y = 0; y < H; ++y)
    for (uint32_t x = 0; x < W; ++x) {
      glm::vec3 sum(0.0f);
      for (int k = 0; k < sub * sub; ++k) {
        const float px = float(x) + (float(k % sub) + 0.5f) / float(sub);
        const float py = float(y) + (float(k / sub) + 0.5f) / float(sub);
        const glm::vec3 eyeDir(2.0f * px / float(W) - 1.0f, 1.0f - 2.0f * py / float(H), -1.0f);
        sum += smoothAt(view.pose.orientation * glm::normalize(eyeDir), W);
      }
      glm::vec3 c = sum / float(sub * sub);
      if (noise > 0.0f) c += glm::vec3(uniform(rng), uniform(rng), uniform(rng));
      img.at(x, y) = glm::vec4(c, 1.0f);
    }
  return img;
}

// Donoho and Johnstone's estimate, written from its definition: the luma's (1, -2, 1) x (1, -2, 1)
// contrast over each sampled pixel's 3x3, divided by its norm 6; sigma = median |d| / Phi^-1(3/4);
// a channel's variance 8/3 sigma^2 (luma = R/4 + G/2 + B/4). The pixels: the centres of blocks of
// blockPx, x, y = blockPx / 2 mod blockPx (2 mod 4: one in 16), inside.
double referenceNoiseVariance(const HostImage& img, uint32_t blockPx = 4) {
  auto luma = [&](uint32_t x, uint32_t y) {
    const glm::vec4 c = img.at(x, y);
    return 0.25 * c.r + 0.5 * c.g + 0.25 * c.b;
  };
  std::vector<double> detail;
  for (uint32_t y = blockPx / 2; y + 1 < img.height; y += blockPx)
    for (uint32_t x = blockPx / 2; x + 1 < img.width; x += blockPx) {
      double contrast = 0.0;
      for (int j = -1; j <= 1; ++j)
        for (int i = -1; i <= 1; ++i)
          contrast += (i == 0 ? -2.0 : 1.0) * (j == 0 ? -2.0 : 1.0) * luma(x + i, y + j);
      detail.push_back(std::abs(contrast) / 6.0);
    }
  std::nth_element(detail.begin(), detail.begin() + detail.size() / 2, detail.end());
  const double sigma = detail[detail.size() / 2] / 0.6744897501960817;
  return sigma * sigma * 8.0 / 3.0;
}

}  // namespace

TEST_F(CoreTest, SteadyEstimatesARendersNoiseFromItsFrames) {
  const uint32_t W = 128, H = 128;
  const float noise = 0.04f;  // uniform: variance noise^2 / 3 per channel
  auto f = makeFilter("steady", steadyNoiseAware(true));
  ASSERT_TRUE(f);
  Rig rig(W, H);
  std::mt19937 rng(5);
  RefView view;
  view.fov = Fov{};
  HostImage img;
  // Round 14: a first frame has no history, so no residual and no estimate; the second has both.
  for (int k = 0; k < 2; ++k) {
    img = render(view, W, H, 1, noise, rng);
    rig.run(*f, Frame{{img, img}, {view, view}}, 1);
    f->waitIdle();
    if (k == 0) {
      EXPECT_FALSE(f->estimatedNoiseVariance().has_value());
    }
  }
  const std::optional<float> estimate = f->estimatedNoiseVariance();
  ASSERT_TRUE(estimate.has_value());
  const double truth = noise * noise / 3.0, reference = referenceNoiseVariance(img);
  // The reference over the same pixels: only the histogram's quarter-octave bins lie between.
  EXPECT_NEAR(*estimate / reference, 1.0, 0.05) << "estimate " << *estimate << ", reference " << reference;
  EXPECT_NEAR(*estimate / truth, 1.0, 0.15) << "estimate " << *estimate << ", noise variance " << truth;
  // Round 14: with a history that has averaged the noise for a while, the residual still holds one
  // frame's noise (through the footprint, whose gain the host divides out), so the estimate stays.
  for (int k = 2; k < 20; ++k) {
    img = render(view, W, H, 1, noise, rng);
    rig.run(*f, Frame{{img, img}, {view, view}}, 1);
  }
  f->waitIdle();
  ASSERT_TRUE(f->estimatedNoiseVariance().has_value());
  EXPECT_NEAR(*f->estimatedNoiseVariance() / truth, 1.0, 0.15) << "after 20 frames";

  // The same picture without noise: its smooth 3x3s carry no diagonal detail.
  auto clean = makeFilter("steady", steadyNoiseAware(true));
  ASSERT_TRUE(clean);
  img = render(view, W, H, 1, 0.0f, rng);
  for (int k = 0; k < 2; ++k) rig.run(*clean, Frame{{img, img}, {view, view}}, 1);
  clean->waitIdle();
  ASSERT_TRUE(clean->estimatedNoiseVariance().has_value());
  EXPECT_LT(*clean->estimatedNoiseVariance(), 0.01 * truth);
  // Off (round 8's default, steady_noise_estimate = 0), nothing is estimated.
  auto off = makeFilter("steady", steadyNoiseAware(false));
  ASSERT_TRUE(off);
  rig.run(*off, Frame{{img, img}, {view, view}}, 1);
  off->waitIdle();
  EXPECT_FALSE(off->estimatedNoiseVariance().has_value());
}

namespace {

// Head tremor (uniform, +-tremorPx centre pixels in yaw and pitch; 0: a still head) over the noisy
// smooth picture: RMSE against the noise-free pixel-area average over the last 16 of 40 frames.
std::optional<double> rmseWithNoise(const std::string& method, bool noiseAware, float tremorPx) {
  const uint32_t W = 48, H = 48;
  auto f = makeFilter(method, steadyNoiseAware(noiseAware));
  if (!f) return std::nullopt;
  Rig rig(W, H);
  std::mt19937 rng(9);  // the same noise and tremor for every method
  const float pxDeg = std::atan(2.0f / float(W)) / kDeg;
  std::uniform_real_distribution<float> tremor(-tremorPx * pxDeg, tremorPx * pxDeg);
  double sum = 0.0;
  for (int k = 0; k < 40; ++k) {
    RefView view;
    view.fov = Fov{};
    const float yaw = tremor(rng), pitch = tremor(rng);
    view.pose.orientation =
        glm::angleAxis(yaw * kDeg, glm::vec3(0, 1, 0)) * glm::angleAxis(pitch * kDeg, glm::vec3(1, 0, 0));
    const HostImage img = render(view, W, H, 1, 0.06f, rng);
    const auto out = rig.run(*f, Frame{{img, img}, {view, view}}, 1);
    std::mt19937 none(0);
    if (k >= 24) sum += rmse(out[0], render(view, W, H, 4, 0.0f, none)) / 16.0;
  }
  return sum;
}

}  // namespace

// Without the estimate the box built from second differences clips a good history to a noisy
// centre, and the clip's t^2 lowers its count: the noise comes through. Measured (lavapipe, RMSE):
// still head: none 0.0346, steady 0.0283, with the estimate 0.0160; under +-0.3 px tremor (the blur
// guard raises alpha there, as before): 0.0346, 0.0279, 0.0230.
// Round 22: the frame's probe takes the noise samples, at the centres of its blocks: 4 px until an eye
// holds more than 2^14 of them, then doubled (filter_passes.h). Above 512x512 an eye the estimate comes
// from fewer pixels than one in 16, spread over the whole frame.
TEST_F(CoreTest, SteadyEstimatesARendersNoiseAtTheProbesBlocksAtEverySize) {
  const float noise = 0.04f;
  const double truth = noise * noise / 3.0;
  for (const auto& [W, blockPx] : {std::pair<uint32_t, uint32_t>{520, 16}, {1040, 32}}) {
    auto f = makeFilter("steady", steadyNoiseAware(true));
    ASSERT_TRUE(f);
    Rig rig(W, W);
    std::mt19937 rng(W);
    RefView view;
    view.fov = Fov{};
    HostImage img;
    for (int k = 0; k < 2; ++k) {  // the second frame has a history: both histograms
      img = render(view, W, W, 1, noise, rng);
      rig.run(*f, Frame{{img, img}, {view, view}}, 1);
    }
    f->waitIdle();
    const std::optional<float> estimate = f->estimatedNoiseVariance();
    ASSERT_TRUE(estimate.has_value()) << W;
    const double reference = referenceNoiseVariance(img, blockPx);
    EXPECT_NEAR(*estimate / reference, 1.0, 0.05)
        << W << ": estimate " << *estimate << ", reference " << reference;
    EXPECT_NEAR(*estimate / truth, 1.0, 0.15)
        << W << ": estimate " << *estimate << ", noise variance " << truth;
  }
}

TEST_F(CoreTest, SteadyWithTheNoiseEstimateAveragesNoise) {
  for (const auto& [tremorPx, bound] : {std::pair{0.0f, 0.7}, std::pair{0.3f, 0.9}}) {
    const auto noneOrNot = rmseWithNoise("none", false, tremorPx);
    const auto steadyOrNot = rmseWithNoise("steady", false, tremorPx);
    const auto awareOrNot = rmseWithNoise("steady", true, tremorPx);
    ASSERT_TRUE(noneOrNot && steadyOrNot && awareOrNot) << "filter creation failed";
    EXPECT_LT(*awareOrNot, bound * *steadyOrNot)
        << "tremor +-" << tremorPx << " px: none " << *noneOrNot << ", steady " << *steadyOrNot
        << ", with the noise estimate " << *awareOrNot;
  }
}

namespace {

// Clean detail as fine as noise, the same in every frame: each pixel a fixed pseudo-random level
// (an aliased texture under a still head; 1-px lines would have no diagonal detail), its contrast
// scaled by `contrast` about mid grey.
HostImage staticFineDetail(uint32_t W, uint32_t H, float contrast) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> level(-0.2f, 0.2f);
  HostImage img(W, H);
  for (auto& px : img.px) {
    const float l = contrast * level(rng);
    px = glm::vec4(0.45f + l, 0.5f + l, 0.4f + l, 1.0f);
  }
  return img;
}

// The estimate after each of `frames` frames of a still head; frame k shows picture(k).
template <typename Picture>
std::vector<std::optional<float>> estimatesOver(bool residualOverTime, int frames, Picture&& picture) {
  const uint32_t W = 128, H = 128;
  auto f = makeFilter("steady", steadyNoiseAware(true, residualOverTime));
  std::vector<std::optional<float>> out;
  if (!f) return out;
  Rig rig(W, H);
  RefView view;
  view.fov = Fov{};
  for (int k = 0; k < frames; ++k) {
    const HostImage img = picture(k, W, H);
    rig.run(*f, Frame{{img, img}, {view, view}}, 1);
    f->waitIdle();
    out.push_back(f->estimatedNoiseVariance());
  }
  return out;
}

}  // namespace

// Round 14: one frame cannot tell fine clean detail from noise (round 13's estimate reads it as
// noise), but the history holds that detail too, so the residual against it is only what the clip
// leaves between them: where the current estimate lies outside the box, the history settles at
// (1 - alpha) of that distance. Measured (lavapipe, per-pixel random levels +-0.2, still head, 14
// frames): round 13's estimate 0.040, round 14's rising from 4e-8 to 2.3e-4 as the history's count
// grows (1/170 of round 13's).
TEST_F(CoreTest, SteadyNoiseEstimateTellsFineDetailThatHoldsFromNoise) {
  auto picture = [](int, uint32_t W, uint32_t H) { return staticFineDetail(W, H, 1.0f); };
  const auto spatialOnly = estimatesOver(false, 14, picture);
  const auto overTime = estimatesOver(true, 14, picture);
  ASSERT_EQ(spatialOnly.size(), 14u);
  ASSERT_EQ(overTime.size(), 14u);
  ASSERT_TRUE(spatialOnly.back() && overTime.back());
  // The detail: levels uniform in +-0.2 on every channel alike, luma variance 0.04 / 3, read as
  // independent channels' noise (x 8/3): about 0.036.
  EXPECT_GT(*spatialOnly.back(), 0.02);
  EXPECT_LT(*overTime.back(), *spatialOnly.back() / 50.0f);
}

// Content that changes in place, for one frame: the residual is the change in that frame (and the
// history's lag after it), and the smallest of the last four frames' residuals is one from before
// it, so the estimate is what it would have been without the change. Measured (lavapipe): equal to
// the unchanged picture's in the three frames after the change; with a window of one frame (planted)
// 11.6x, 5.2x and 3.9x it (the change, then the history's lag behind it).
TEST_F(CoreTest, SteadyNoiseEstimateLetsAChangeInPlacePass) {
  constexpr int kChange = 10, kFrames = kChange + 3;
  auto unchanged = [](int, uint32_t W, uint32_t H) { return staticFineDetail(W, H, 1.0f); };
  auto changed = [](int k, uint32_t W, uint32_t H) {
    return staticFineDetail(W, H, k < kChange ? 1.0f : 0.7f);
  };
  const auto withoutChange = estimatesOver(true, kFrames, unchanged);
  const auto withChange = estimatesOver(true, kFrames, changed);
  ASSERT_EQ(withoutChange.size(), size_t{kFrames});
  ASSERT_EQ(withChange.size(), size_t{kFrames});
  for (int k = kChange; k < kFrames; ++k) {
    ASSERT_TRUE(withoutChange[k] && withChange[k]) << "frame " << k;
    EXPECT_LE(*withChange[k], 1.01f * *withoutChange[k]) << "frame " << k;
  }
}

// A GPU runs one pixel per invocation, a CPU device 4x4 (Params::invocationBlock): the sampled pixels,
// their frame and residual details and so the estimate are the same either way (here both on
// lavapipe), for noise and for clean fine detail.
TEST_F(CoreTest, SteadyNoiseEstimateIsTheSameOnePixelOrBlockPerInvocation) {
  const uint32_t W = 70, H = 54;  // not a multiple of the block
  for (const float noise : {0.04f, 0.0f}) {
    std::array<std::optional<float>, 2> estimates;
    for (int b = 0; b < 2; ++b) {
      Params p = steadyNoiseAware(true);
      p.invocationBlock = b == 0 ? InvocationBlock::OnePixel : InvocationBlock::FourByFour;
      auto f = makeFilter("steady", p);
      ASSERT_TRUE(f);
      Rig rig(W, H);
      std::mt19937 rng(3);
      RefView view;
      view.fov = Fov{};
      for (int k = 0; k < 6; ++k) {
        const HostImage img = noise > 0.0f ? render(view, W, H, 1, noise, rng) : staticFineDetail(W, H, 1.0f);
        rig.run(*f, Frame{{img, img}, {view, view}}, 1);
      }
      f->waitIdle();
      estimates[size_t(b)] = f->estimatedNoiseVariance();
    }
    ASSERT_TRUE(estimates[0] && estimates[1]) << noise;
    EXPECT_NEAR(*estimates[0], *estimates[1], 1e-3f * *estimates[1] + 1e-12f) << "noise " << noise;
  }
}

// Round 15: a fade of a noisy picture. Its residual against the history has a mean over the frame
// (every pixel darker than the history that lags it) in every frame, noise's has none, so the
// estimate is 0 while the picture fades (the default's box: a box widened by the noise would let the
// fade's lag through) and the noise's before the fade. Without the test (round 14's) the estimate
// holds through the fade. Measured (lavapipe, 128^2, uniform noise +-0.04, 1 % darker each frame):
// before the fade 1.00-1.20x the truth; 0 from the fade's second frame; round 14's near the truth.
TEST_F(CoreTest, SteadyNoiseEstimateIsNoneWhileThePictureFades) {
  const uint32_t W = 128, H = 128;
  const float noise = 0.04f, truth = noise * noise / 3.0f;
  constexpr int kFadeStart = 10, kFrames = 18;
  for (const bool changeTest : {true, false}) {
    auto f = makeFilter("steady", steadyNoiseAware(true, true, changeTest));
    ASSERT_TRUE(f);
    Rig rig(W, H);
    std::mt19937 rng(11);
    RefView view;
    view.fov = Fov{};
    for (int k = 0; k < kFrames; ++k) {
      HostImage img = render(view, W, H, 1, noise, rng);
      const float light = k < kFadeStart ? 1.0f : 1.0f - 0.01f * float(k - kFadeStart + 1);
      for (auto& px : img.px) px = glm::vec4(glm::vec3(px) * light, px.a);
      rig.run(*f, Frame{{img, img}, {view, view}}, 1);
      f->waitIdle();
      if (k == 0) continue;  // no history, no residual: no estimate yet
      const std::optional<float> estimate = f->estimatedNoiseVariance();
      ASSERT_TRUE(estimate.has_value()) << "frame " << k;
      if (k <= kFadeStart || !changeTest)  // its accuracy: SteadyEstimatesARendersNoiseFromItsFrames
        EXPECT_NEAR(*estimate / truth, 1.0, 0.3) << "frame " << k << ", change test " << changeTest;
      else  // from the fade's second frame: two frames whose residual's mean lies on one side
        EXPECT_EQ(*estimate, 0.0f) << "frame " << k << " (fading)";
    }
  }
}

// The allowance itself, from its derivation: independent noise of variance v in each RGB channel has
// variance v |r|^2 in the YCoCg channel with row r (Y = R/4 + G/2 + B/4: 3v/8; Co = (R - B)/2: v/2;
// Cg = -R/4 + G/2 - B/4: 3v/8), and the box's half-width squared grows by it. A flat grey field, then
// the same field with red raised by delta: the history differs from the new box centre by
// (-delta/4, -delta/2, delta/4), so Co decides, and the history stays (is not clipped) while
// delta^2 / 4 <= v / 2 + the half-step floor. Kept, a history of one frame is averaged with the frame:
// red is the mean of the two; clipped, it comes out nearer the new frame.
TEST_F(CoreTest, SteadyBoxWidensByTheToldNoiseInEachYCoCgChannel) {
  const uint32_t W = 16, H = 16;
  const float v = 1e-3f;  // noise variance per RGB channel (sigma about 0.032)
  for (const float deltaSquaredOverV : {1.5f, 3.0f}) {
    Params p = steadyNoiseAware(false);
    p.steadyNoiseVariance = v;
    auto f = makeFilter("steady", p);
    ASSERT_TRUE(f);
    Rig rig(W, H);
    RefView view;
    view.fov = Fov{};
    const float delta = std::sqrt(deltaSquaredOverV * v);
    HostImage grey(W, H), redder(W, H);
    for (auto& px : grey.px) px = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
    for (auto& px : redder.px) px = glm::vec4(0.5f + delta, 0.5f, 0.5f, 1.0f);
    rig.run(*f, Frame{{grey, grey}, {view, view}}, 1);
    const auto out = rig.run(*f, Frame{{redder, redder}, {view, view}}, 1);
    const float red = out[0].at(W / 2, H / 2).r, mean = 0.5f + 0.5f * delta;
    if (deltaSquaredOverV < 2.0f)  // Co: delta^2 / 4 = 0.375 v < v / 2: kept
      EXPECT_NEAR(red, mean, 1e-3f) << "delta^2 = " << deltaSquaredOverV << " v";
    else  // 0.75 v > v / 2: clipped, and its count cut
      EXPECT_GT(red, mean + 0.1f * delta) << "delta^2 = " << deltaSquaredOverV << " v";
  }
}
