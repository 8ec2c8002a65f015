// Params::steadyOutputHold on real Vulkan: an 8-bit output with hysteresis. The rule, written from
// its statement (params.h), not from the shader: each channel keeps the code it showed last frame
// while the unrounded estimate lies within 1/2 + hold codes of it and moved by less than half a code
// since last frame, and rounds elsewhere. The
// estimate is the same filter's on an RGBA16F target (a float output is not held, and the hold
// never touches the history, so both filters see the same history frame after frame). Where the
// picture moved half a pixel or more the hold lets go: the output is plain rounding's to the bit, away
// from rounding ties (which a device breaks its own way).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <utility>

#include "filter_test_rig.h"
#include "reference.h"

using namespace steadyxr;
using namespace steadyxr::core;
using namespace steadyxr::test;

namespace {

constexpr uint32_t kW = 16, kH = 16;
constexpr int kFrames = 24;

// A ramp of one code every 4 px with a checker of one code that swaps every frame: aliasing under a
// still head. The estimate settles near the middle of each checker pixel's two codes and hovers there.
HostImage flickerFrame(int k, bool srgb) {
  HostImage img(kW, kH);
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < kW; ++x) {
      const int code = 96 + int(x) / 4 + int((x + y + uint32_t(k)) % 2);
      const float v = srgb ? float(srgbDecode(code / 255.0)) : code / 255.0f;
      img.at(x, y) = glm::vec4(v, v, v, 1.0f);
    }
  return img;
}

double toCode(float v, bool srgb) {
  return 255.0 * (srgb ? srgbEncode(std::clamp(double(v), 0.0, 1.0)) : double(v));
}

struct HoldRun {
  int ruleMismatches = 0;  // decisions the output got wrong, where the readback decides them
  int nearThreshold = 0;   // decisions an error of kAmbiguous in the estimates read back could change
  int decisions = 0;
  int heldChanges = 0;       // times a channel's shown code changed from one frame to the next
  int roundedChanges = 0;    // the same for the estimate rounded
  double worstDistance = 0;  // codes between the shown code and the estimate
};

// The estimate is read back in half precision: half an ulp is 0.03 of a code at UNORM code 100
// (linear 0.39), 0.02 at sRGB code 97 (linear 0.12). A decision that an error this large in either
// estimate could change is not checked. Only the outcome counts: an estimate that hovers at a rounding
// boundary (as it does on a device whose sRGB decode is exact, e.g. an H100) is checked while the
// rule keeps last frame's code there.
constexpr double kAmbiguous = 0.04;

// The rule (params.h): the code shown for estimate `code`, given last frame's shown code and estimate.
double heldCode(double code, double last, double before, double threshold) {
  const bool keep = std::abs(code - last) <= threshold && std::abs(code - before) <= 0.5;
  return keep ? last : std::round(code);
}

// Whether an error of up to kAmbiguous in `code` or `before` could change heldCode's answer.
bool ambiguousDecision(double code, double last, double before, double threshold) {
  const double expected = heldCode(code, last, before, threshold);
  constexpr int kSteps = 8;  // the breakpoints are at least 1/4 of a code apart, the steps 0.01
  for (int i = -kSteps; i <= kSteps; ++i)
    for (int j = -1; j <= 1; ++j) {
      const double dc = kAmbiguous * i / kSteps, db = kAmbiguous * j;
      if (heldCode(code + dc, last, before + db, threshold) != expected) return true;
    }
  return false;
}

std::optional<HoldRun> runFlicker(float hold, bool srgb) {
  Params p = *applyMethodName("steady");
  p.steadyOutputHold = hold;
  auto held = makeFilter("steady", p), estimate = makeFilter("steady", p);
  if (!held || !estimate) return std::nullopt;
  const VkFormat fmt8 = srgb ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_R8G8B8A8_UNORM;
  Rig heldRig(kW, kH, fmt8, fmt8, VK_IMAGE_USAGE_STORAGE_BIT, srgb);  // sRGB: written through a UNORM view
  Rig floatRig(kW, kH, fmt8, VK_FORMAT_R16G16B16A16_SFLOAT);
  HoldRun r;
  HostImage lastShown, lastEstimate;
  const double threshold = 0.5 + hold;
  for (int k = 0; k < kFrames; ++k) {
    const HostImage img = flickerFrame(k, srgb);
    const Frame frame{{img, img}, {eye(0, 0), eye(0, 0)}};
    const HostImage shown = heldRig.run(*held, frame, 1)[0], est = floatRig.run(*estimate, frame, 1)[0];
    for (size_t i = 0; i < shown.px.size(); ++i)
      for (int ch = 0; ch < 3; ++ch) {
        const double code = toCode(est.px[i][ch], srgb), out = std::round(toCode(shown.px[i][ch], srgb));
        r.worstDistance = std::max(r.worstDistance, std::abs(out - code));
        if (k == 0) continue;
        // A still head: the reprojection comes from the pixel itself.
        const double last = std::round(toCode(lastShown.px[i][ch], srgb));
        const double before = toCode(lastEstimate.px[i][ch], srgb);
        ++r.decisions;
        if (ambiguousDecision(code, last, before, threshold))
          ++r.nearThreshold;
        else if (out != heldCode(code, last, before, threshold))
          ++r.ruleMismatches;
        r.heldChanges += out != last ? 1 : 0;
        r.roundedChanges += std::round(code) != std::round(before) ? 1 : 0;
      }
    lastShown = shown;
    lastEstimate = est;
  }
  return r;
}

void expectHeld(const HoldRun& r, float hold, const char* what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(r.ruleMismatches, 0) << "of " << r.decisions << " decisions";
  EXPECT_LT(r.nearThreshold, r.decisions / 10) << "too few decisions away from a threshold to check";
  EXPECT_LE(r.worstDistance, 0.5 + hold + kAmbiguous);
  // The scene must make rounding flip, or the test checks nothing; the hold must then flip far less
  // (measured: 0.37 and 0.47 of rounding's flips; the rest are the estimate's own steps of a code).
  EXPECT_GT(r.roundedChanges, 100);
  EXPECT_LT(r.heldChanges * 3, r.roundedChanges * 2) << r.roundedChanges << " flips rounded";
}

}  // namespace

// An estimate that hovers at a code boundary: plain rounding flips the output back and forth, the hold
// keeps last frame's code while the estimate stays within 1/2 + hold of it, and never strays further.
TEST_F(CoreTest, SteadyOutputHoldKeepsLastCodeWhereTheEstimateHovers) {
  constexpr float kHold = 0.25f;
  const std::optional<HoldRun> unorm = runFlicker(kHold, false), srgb = runFlicker(kHold, true);
  ASSERT_TRUE(unorm && srgb) << "filter creation failed";
  expectHeld(*unorm, kHold, "UNORM output (the codes themselves)");
  expectHeld(*srgb, kHold, "sRGB output (the pass encodes)");
}

// hold = 0 is plain rounding: the output is the estimate rounded, and flips with it.
TEST_F(CoreTest, SteadyOutputHoldOffRoundsTheEstimate) {
  const std::optional<HoldRun> r = runFlicker(0.0f, false);
  ASSERT_TRUE(r) << "filter creation failed";
  EXPECT_EQ(r->ruleMismatches, 0) << "of " << r->decisions << " decisions";
  EXPECT_LE(r->worstDistance, 0.5 + kAmbiguous);
  EXPECT_GT(r->roundedChanges, 100);
}

namespace {

// The default with the hold (1/4) and with plain rounding, each on its own UNORM rig, and the estimate
// (the held filter's, on an RGBA16F rig): one frame through all three.
struct HeldRoundedEstimate {
  HostImage held, rounded, estimate;
};
class HeldAndRounded {
 public:
  bool ok() const { return held_ && rounded_ && estimate_; }
  HeldRoundedEstimate run(const Frame& frame) {
    return {heldRig_.run(*held_, frame, 1)[0], roundedRig_.run(*rounded_, frame, 1)[0],
            estimateRig_.run(*estimate_, frame, 1)[0]};
  }

 private:
  static Params withHold(float hold) {
    Params p = *applyMethodName("steady");
    p.steadyOutputHold = hold;
    return p;
  }
  std::unique_ptr<Filter> held_ = makeFilter("steady", withHold(0.25f)),
                          rounded_ = makeFilter("steady", withHold(0.0f)),
                          estimate_ = makeFilter("steady", withHold(0.25f));
  Rig heldRig_{kW, kH, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM},
      roundedRig_{kW, kH, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM},
      estimateRig_{kW, kH, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R16G16B16A16_SFLOAT};
};

struct Differences {
  int differ = 0;   // output channels where the held filter and plain rounding differ
  int checked = 0;  // channels compared: a rounding tie within the estimate's readback is not
  int total = 0;
  double worstDistance = 0;  // codes between the held output and the estimate
};

// The flicker frames under a head that swings between two yaws `swingDeg` apart (0.19 px a degree at
// this size and fov: 5 degrees move every pixel by about a pixel, past the half where the hold ends), through
// a held filter and one with plain rounding: where the two differ over the run. A channel whose estimate
// lies within kAmbiguous of a rounding tie is left out: a device breaks a tie its own way, and on an H100
// a UNORM store and the shader's round() broke 504 of them differently.
// `frameAt` gives frame k (by default the flicker frames; a smaller one is a smaller render size).
std::optional<Differences> heldAgainstRounded(
    float swingDeg,
    const std::function<HostImage(int)>& frameAt = [](int k) { return flickerFrame(k, false); }) {
  HeldAndRounded filters;
  if (!filters.ok()) return std::nullopt;
  Differences d;
  for (int k = 0; k < kFrames; ++k) {
    const HostImage img = frameAt(k);
    const RefView view = eye(float(k % 2) * swingDeg, 0.0f);
    const HeldRoundedEstimate out = filters.run(Frame{{img, img}, {view, view}});
    for (size_t i = 0; i < out.held.px.size(); ++i)
      for (int ch = 0; ch < 3; ++ch) {
        ++d.total;
        const double code = toCode(out.estimate.px[i][ch], false);
        d.worstDistance = std::max(d.worstDistance, std::abs(toCode(out.held.px[i][ch], false) - code));
        if (std::round(code - kAmbiguous) != std::round(code + kAmbiguous)) continue;
        ++d.checked;
        d.differ += out.held.px[i][ch] != out.rounded.px[i][ch] ? 1 : 0;
      }
  }
  return d;
}

}  // namespace

// The hold is for a picture that stood still: where it moved half a pixel or more since last frame, the
// code of last frame's texel may be a neighbour's, and the output is plain rounding's to the bit away from
// rounding ties. Under a still head the same frames are held (so the comparison can tell the two apart).
TEST_F(CoreTest, SteadyOutputHoldLetsGoWhereThePictureMoved) {
  const std::optional<Differences> still = heldAgainstRounded(0.0f), swinging = heldAgainstRounded(5.0f);
  ASSERT_TRUE(still && swinging) << "filter creation failed";
  EXPECT_GT(still->differ, 100) << "the still head's frames should be held";
  EXPECT_EQ(swinging->differ, 0) << "channels held where the picture moved a pixel";
  EXPECT_GT(swinging->checked * 10, swinging->total * 9) << "too many rounding ties to tell";
}

namespace {

// Frame k of a still picture at size x size px: a ramp of four codes across the view (the same picture at
// every size, point-sampled at pixel centres) with noise of +-0.4 of a code that changes every frame. The
// estimate averages the noise and hovers at the ramp's code boundaries, where rounding flips.
HostImage noisyRamp(int k, uint32_t size) {
  std::mt19937 rng(uint32_t(k) + 1);
  std::uniform_real_distribution<float> noise(-0.4f, 0.4f);
  HostImage img(size, size);
  for (uint32_t y = 0; y < size; ++y)
    for (uint32_t x = 0; x < size; ++x) {
      const float v = (96.0f + 4.0f * (float(x) + 0.5f) / float(size) + noise(rng)) / 255.0f;
      img.at(x, y) = glm::vec4(v, v, v, 1.0f);
    }
  return img;
}

}  // namespace

// An app that changes its render size every frame (16 and 12 px in turn; round 39): last frame's codes are
// of another size's pixels, so the output is plain rounding's (away from rounding ties) for a still
// picture and a swinging one alike; at a fixed size the same still picture is held (so the comparison can
// tell). Planted: the move measured between the two grids (the hold kept 3 and, swinging, 6 channels near
// the corner where the grids meet); the move measured in this frame's pixels (the hold kept a still picture's
// codes across the change, which on the corpus at 1, 0.75 gave a slightly higher RMSE and shimmer).
TEST_F(CoreTest, SteadyOutputHoldRoundsAcrossChangesOfRenderSize) {
  const auto fixedSize = [](int k) { return noisyRamp(k, kW); };
  const auto changingSize = [](int k) { return noisyRamp(k, k % 2 == 0 ? kW : kW * 3 / 4); };
  const std::optional<Differences> fixed = heldAgainstRounded(0.0f, fixedSize),
                                   still = heldAgainstRounded(0.0f, changingSize),
                                   swinging = heldAgainstRounded(5.0f, changingSize);
  ASSERT_TRUE(fixed && still && swinging) << "filter creation failed";
  EXPECT_GT(fixed->differ, 100) << "of " << fixed->checked << ": at a fixed size the picture should be held";
  EXPECT_EQ(still->differ, 0) << "channels held across a change of size, of " << still->checked;
  EXPECT_EQ(swinging->differ, 0) << "channels held across a change of size, of " << swinging->checked;
  EXPECT_GT(still->checked * 10, still->total * 9) << "too many rounding ties to tell";
  EXPECT_LE(still->worstDistance, 0.5 + kAmbiguous);
}

namespace {

// A ramp fading down by 0.8 % a frame (about 0.8 of a code at code 100), still head, UNORM: the largest
// step of any output channel from one frame to the next, in codes, for the held output and the rounded.
std::optional<std::pair<double, double>> fadeSteps() {
  HeldAndRounded filters;
  if (!filters.ok()) return std::nullopt;
  double heldStep = 0, roundedStep = 0;
  HostImage lastF, lastG;
  for (int k = 0; k < kFrames; ++k) {
    HostImage img(kW, kH);
    const float gain = 1.0f - 0.008f * float(std::max(0, k - 4));  // still for 4 frames, then the fade
    for (uint32_t y = 0; y < kH; ++y)
      for (uint32_t x = 0; x < kW; ++x) {
        const float v = gain * float(96 + int(x)) / 255.0f;
        img.at(x, y) = glm::vec4(v, v, v, 1.0f);
      }
    const HeldRoundedEstimate out = filters.run(Frame{{img, img}, {eye(0, 0), eye(0, 0)}});
    const HostImage &a = out.held, &b = out.rounded;
    if (k > 4)
      for (size_t i = 0; i < a.px.size(); ++i)
        for (int ch = 0; ch < 3; ++ch) {
          heldStep = std::max(heldStep, 255.0 * std::abs(double(a.px[i][ch]) - double(lastF.px[i][ch])));
          roundedStep =
              std::max(roundedStep, 255.0 * std::abs(double(b.px[i][ch]) - double(lastG.px[i][ch])));
        }
    lastF = a;
    lastG = b;
  }
  return std::make_pair(heldStep, roundedStep);
}

}  // namespace

// A steady change is not hovering: a fade of 0.8 of a code a frame is shown code by code, as rounding
// shows it. Held without regard to how far the estimate moved, it went in steps of two codes every other
// frame (a fade at 90 Hz on held-out seed 52: 3.8x none's temporal error).
TEST_F(CoreTest, SteadyOutputHoldShowsASteadyFadeCodeByCode) {
  const auto steps = fadeSteps();
  ASSERT_TRUE(steps) << "filter creation failed";
  EXPECT_LE(steps->second, 1.0 + 1e-3) << "rounded: the fade itself should move by at most a code a frame";
  EXPECT_LE(steps->first, 1.0 + 1e-3) << "held: a step of more than one code";
}
