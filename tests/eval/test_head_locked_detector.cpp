// Round 41's study (eval/head_locked_detector.h): pictures drawn here on the CPU from the geometry (a
// texture fixed to the world's directions, a patch fixed to the screen), not from the detector's code.
#include "head_locked_detector.h"

#include "config.h"  // layer/xr/src: the layer's own config parser, for its profile hud

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>

namespace steadyxr::eval {
namespace {

constexpr int kSide = 96;
constexpr float kDegToRad = float(std::numbers::pi / 180.0);

EyeCamera cameraAtYaw(float yawDeg, float pitchDeg, float rollDeg = 0.0f) {
  core::Pose pose;
  pose.orientation = glm::angleAxis(yawDeg * kDegToRad, glm::vec3(0, 1, 0)) *
                     glm::angleAxis(pitchDeg * kDegToRad, glm::vec3(1, 0, 0)) *
                     glm::angleAxis(rollDeg * kDegToRad, glm::vec3(0, 0, 1));
  const core::Fov fov{-0.785f, 0.785f, 0.785f, -0.785f};  // 90 degrees: about 1 px a degree at 96 px
  return makeEyeCamera(pose, fov, kSide, kSide);
}

// A world texture of a few incommensurate waves over the view direction (periods of 6-20 degrees, so a
// few pixels), and, with `patch`, a screen-fixed block of sharp stripes (a HUD's text), 32 x 16 px with its
// top left corner at `corner` (by default at x 30-61, y 40-55, around the centre).
Image draw(const EyeCamera& cam, bool patch, glm::ivec2 corner = {30, 40}) {
  Image image(kSide, kSide);
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x) {
      float value;
      if (patch && x >= corner.x && x < corner.x + 32 && y >= corner.y && y < corner.y + 16) {
        value = ((x / 3 + y / 4) % 2) != 0 ? 0.95f : 0.1f;
      } else {
        const glm::vec3 d = pixelDirection(cam, float(x) + 0.5f, float(y) + 0.5f);
        const float azimuth = std::atan2(d.x, -d.z), elevation = std::asin(d.y);
        value = 0.5f + 0.22f * std::sin(45.0f * azimuth + 1.0f) + 0.18f * std::sin(31.0f * elevation) +
                0.08f * std::sin(17.0f * azimuth + 23.0f * elevation);
      }
      float* c = image.at(x, y);
      c[0] = c[1] = c[2] = std::round(value * 255.0f) / 255.0f;  // 8-bit, as the app's swapchain
    }
  return image;
}

// A head that turns back and forth by `amplitudeDeg` over 24 frames (a shake), for `frames` frames.
HeadLockedDetector run(bool patch, float amplitudeDeg, int frames) {
  HeadLockedDetector detector;
  for (int f = 0; f < frames; ++f) {
    const float phase = 2.0f * float(std::numbers::pi) * float(f) / 24.0f;
    const EyeCamera cam =
        cameraAtYaw(amplitudeDeg * std::sin(phase), 0.3f * amplitudeDeg * std::sin(2.0f * phase));
    const Image image = draw(cam, patch);
    detector.observe(f, {&image, &image}, {cam, cam});
  }
  return detector;
}

TEST(HeadLockedDetector, FindsAScreenFixedPatchOnceTheHeadMoves) {
  const HeadLockedDetector d = run(true, 8.0f, 48);
  ASSERT_TRUE(d.decided());
  EXPECT_GT(d.decidedFrame(), 0);
  EXPECT_GE(d.epochs().size(), 2u);
}

TEST(HeadLockedDetector, OneEpochsEvidenceIsNotEnough) {
  // The patch is drawn only until the first epoch ends (in that frame too): its samples testify once.
  HeadLockedDetector d;
  for (int f = 0; f < 48; ++f) {
    const float phase = 2.0f * float(std::numbers::pi) * float(f) / 24.0f;
    const EyeCamera cam = cameraAtYaw(8.0f * std::sin(phase), 2.4f * std::sin(2.0f * phase));
    const bool firstEpoch = d.epochs().empty();
    const Image image = draw(cam, firstEpoch);
    d.observe(f, {&image, &image}, {cam, cam});
    if (firstEpoch && !d.epochs().empty()) {
      EXPECT_GE(d.epochs().front().headLocked, HeadLockedDetector::kEvidenceSamples);  // it did testify
    }
  }
  ASSERT_GE(d.epochs().size(), 4u);
  EXPECT_FALSE(d.decided()) << "decided in frame " << d.decidedFrame();
}

TEST(HeadLockedDetector, ASampleTestifiesOnceAnEpoch) {
  // A steady roll moves the image's corners a pixel every few frames and its centre hardly at all, so the
  // corners' samples pass 2 px several frames before half of the samples have and the epoch ends. A patch
  // in a corner, drawn only until then, must testify once (not once a frame) and so decides nothing.
  HeadLockedDetector d;
  for (int f = 0; f < 48; ++f) {
    const EyeCamera cam = cameraAtYaw(0.0f, 0.0f, 0.5f * float(f));
    const bool firstEpoch = d.epochs().empty();
    const Image image = draw(cam, firstEpoch, {4, 4});
    d.observe(f, {&image, &image}, {cam, cam});
  }
  ASSERT_GE(d.epochs().size(), 2u);
  EXPECT_FALSE(d.decided()) << "decided in frame " << d.decidedFrame();
}

TEST(HeadLockedDetector, NeverDecidesOnAWorldAlone) {
  const HeadLockedDetector d = run(false, 8.0f, 48);
  EXPECT_FALSE(d.decided());
  ASSERT_GE(d.epochs().size(), 4u);  // it did judge: the world testified in every epoch
  for (const HeadLockedEpoch& e : d.epochs()) {
    EXPECT_GT(e.world, 20) << "epoch ending in frame " << e.frame;
    EXPECT_LT(e.headLocked, HeadLockedDetector::kEvidenceSamples) << "epoch ending in frame " << e.frame;
  }
}

TEST(HeadLockedDetector, AHeadThatMovesLessThanTheShiftJudgesNothing) {
  // 1 degree peak: about a pixel, under kShiftPx, so no epoch ends and nothing is decided.
  const HeadLockedDetector d = run(true, 1.0f, 48);
  EXPECT_TRUE(d.epochs().empty());
  EXPECT_FALSE(d.decided());
}

TEST(HeadLockedDetector, TheProfileIsTheLayers) {
  // The layer's own parser resolves `profile = hud` (layer/xr/src/config.cpp): the study's switch must set
  // what it sets, and keep the rest.
  std::vector<std::string> messages;
  const layer::EnvLookup noEnvironment = [](const std::string&) -> std::optional<std::string> { return {}; };
  const layer::Config plain = layer::resolveConfig({}, "app", noEnvironment, &messages);
  const layer::Config hud = layer::resolveConfig(layer::parseConfigText("profile = hud\n", &messages), "app",
                                                 noEnvironment, &messages);
  ASSERT_TRUE(messages.empty()) << messages.front();
  ASSERT_NE(plain.params.steadyBlurBudgetPx2, hud.params.steadyBlurBudgetPx2);  // the profile changes both
  ASSERT_NE(plain.params.steadyClipHoldsCurrent, hud.params.steadyClipHoldsCurrent);
  core::Params told = plain.params;
  told.steadyNoiseEstimate = !told.steadyNoiseEstimate;
  const core::Params switched = core::withHudProfile(told);
  EXPECT_EQ(switched.steadyBlurBudgetPx2, hud.params.steadyBlurBudgetPx2);
  EXPECT_EQ(switched.steadyClipHoldsCurrent, hud.params.steadyClipHoldsCurrent);
  EXPECT_EQ(switched.steadyNoiseEstimate, told.steadyNoiseEstimate);  // everything else kept
}

}  // namespace
}  // namespace steadyxr::eval
