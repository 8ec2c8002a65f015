// Params::steadyUnexplainedFrameResets (round 31, item 13) on real Vulkan: a frame whose history,
// reprojected through the pose it was submitted with, is no closer to it over 4x4-pixel blocks than the
// frame's blocks are to their neighbours starts every pixel afresh; a picture the pose explains, a fade and a
// render's noise do not.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "filter_test_rig.h"
#include "reference.h"

using namespace steadyxr;
using namespace steadyxr::core;
using namespace steadyxr::test;

namespace {

// The default's temporal pass without the render-noise estimate (its box would widen by the noise),
// with the test on or off.
Params steadyCut(bool on) {
  Params p = *applyMethodName("steady");
  p.steadyNoiseEstimate = false;
  p.steadyUnexplainedFrameResets = on;
  return p;
}

// Waves of period 64 px along x and y, moved `shiftPx` to the right, under a 1-px checker that stays (a
// repeating texture: in a 3x3 the checker's spread admits much of a history whose waves are misplaced).
// Over 4x4 blocks the checker averages out; moved by s, a block differs from its old value by
// sin(pi s / 64) / sin(pi 4 / 64) of the mean step between blocks: 3.6 at s = 16, 0.13 at s = 1/2.
HostImage wavesUnderChecker(uint32_t w, uint32_t h, float shiftPx) {
  constexpr float kTwoPi = 6.28318530718f, kPeriodPx = 64.0f;
  HostImage img(w, h);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const float waves = 0.5f + 0.15f * std::sin(kTwoPi * (float(x) + 0.5f - shiftPx) / kPeriodPx) +
                          0.15f * std::sin(kTwoPi * (float(y) + 0.5f) / kPeriodPx + 1.0f);
      const float v = waves + ((x + y) % 2 ? 0.1f : -0.1f);
      img.at(x, y) = glm::vec4(v, 0.9f * v, 0.8f * v, 1.0f);
    }
  return toHalf(img);
}

// `before` held 16 frames (a settled history), then `after` once, both at the same pose: the output of
// that frame, with the test on or off.
std::optional<HostImage> afterSettled(bool on, const HostImage& before, const HostImage& after) {
  auto f = makeFilter("steady", steadyCut(on));
  if (!f) return std::nullopt;
  Rig rig(before.width, before.height);
  for (int k = 0; k < 16; ++k) rig.run(*f, Frame{{before, before}, {eye(0, 0), eye(0, 0)}}, 1);
  return rig.run(*f, Frame{{after, after}, {eye(0, 0), eye(0, 0)}}, 1)[0];
}

// What a filter shows for `picture` as its first frame: nothing to reproject, its own estimate.
std::optional<HostImage> firstFrame(const HostImage& picture) {
  auto f = makeFilter("steady", steadyCut(true));
  if (!f) return std::nullopt;
  Rig rig(picture.width, picture.height);
  return rig.run(*f, Frame{{picture, picture}, {eye(0, 0), eye(0, 0)}}, 1)[0];
}

// The blocks' sums by their definition: at the probe's samples (the centres (2 + 4i, 2 + 4j) of 4 px
// blocks here, sample (i, j)), the luma (R + 2G + B) / 4 averaged over the 4x4 pixels x - 1 .. x + 2,
// y - 1 .. y + 2 (the edge pixel repeated): its |change| from the same block of `before` (a still pose:
// the history is the last output), and its |step| to the block 4 px to the right where i + j is even, 4 px
// below where it is odd. A neighbour is read as four 2x2 quads kept inside the image (a quad's corner at
// most a pixel from the edge). Round 33: each block's structure, the mean of |left half - right half| and
// |top half - bottom half| (the halves' mean lumas, 8 pixels each), in `now` and in `before`.
struct BlockSums {
  double meanChange = 0.0, meanStep = 0.0, meanStructure = 0.0, meanStructureBefore = 0.0;
};
BlockSums blockSumsByDefinition(const HostImage& now, const HostImage& before) {
  const auto luma = [](const HostImage& img, int x, int y) {
    const glm::vec4 c = img.at(uint32_t(std::clamp(x, 0, int(img.width) - 1)),
                               uint32_t(std::clamp(y, 0, int(img.height) - 1)));
    return 0.25 * c.r + 0.5 * c.g + 0.25 * c.b;
  };
  // The quad whose corner is (cx, cy): pixels cx - 1 and cx by cy - 1 and cy.
  const auto quadLuma = [&](const HostImage& img, int cx, int cy, bool keptInside) {
    if (keptInside) {
      cx = std::clamp(cx, 1, int(img.width) - 1);
      cy = std::clamp(cy, 1, int(img.height) - 1);
    }
    return 0.25 *
           (luma(img, cx - 1, cy - 1) + luma(img, cx, cy - 1) + luma(img, cx - 1, cy) + luma(img, cx, cy));
  };
  const auto blockLuma = [&](const HostImage& img, int x, int y, bool keptInside) {
    return 0.25 * (quadLuma(img, x, y, keptInside) + quadLuma(img, x + 2, y, keptInside) +
                   quadLuma(img, x, y + 2, keptInside) + quadLuma(img, x + 2, y + 2, keptInside));
  };
  const auto structure = [&](const HostImage& img, int x, int y) {
    double left = 0.0, right = 0.0, top = 0.0, bottom = 0.0;
    for (int dy = -1; dy <= 2; ++dy)
      for (int dx = -1; dx <= 2; ++dx) {
        const double v = luma(img, x + dx, y + dy) / 8.0;
        (dx <= 0 ? left : right) += v;
        (dy <= 0 ? top : bottom) += v;
      }
    return 0.5 * (std::abs(left - right) + std::abs(top - bottom));
  };
  BlockSums sums;
  int samples = 0;
  for (int j = 0, y = 2; y < int(now.height); ++j, y += 4)
    for (int i = 0, x = 2; x < int(now.width); ++i, x += 4) {
      const double block = blockLuma(now, x, y, false);
      const bool across = (i + j) % 2 == 0;
      sums.meanChange += std::min(std::abs(block - blockLuma(before, x, y, false)), 0.5);
      sums.meanStep +=
          std::min(std::abs(blockLuma(now, across ? x + 4 : x, across ? y : y + 4, true) - block), 0.5);
      sums.meanStructure += std::min(structure(now, x, y), 0.5);
      sums.meanStructureBefore += std::min(structure(before, x, y), 0.5);
      ++samples;
    }
  sums.meanChange /= samples;
  sums.meanStep /= samples;
  sums.meanStructure /= samples;
  sums.meanStructureBefore /= samples;
  return sums;
}

}  // namespace

// The probe's record holds the blocks' mean change and step, to its rounding (2^-11 a sample).
TEST_F(CoreTest, SteadyProbeSumsTheFramesBlocks) {
  const uint32_t W = 64, H = 48;
  const HostImage first = toHalf(pattern(W, H, 5)), second = toHalf(pattern(W, H, 6, 0.1f));
  auto f = makeFilter("steady", steadyCut(true));
  ASSERT_TRUE(f) << "filter creation failed";
  Rig rig(W, H);
  const HostImage firstOut = rig.run(*f, Frame{{first, first}, {eye(0, 0), eye(0, 0)}}, 1)[0];
  rig.run(*f, Frame{{second, second}, {eye(0, 0), eye(0, 0)}}, 1);
  f->waitIdle();
  const std::optional<GainProbeSums> got = f->lastGainProbe();
  ASSERT_TRUE(got) << "no probe with samples";
  const BlockSums want = blockSumsByDefinition(second, firstOut);
  EXPECT_GT(want.meanChange, 0.005) << "the premise: blocks that changed";
  EXPECT_GT(want.meanStep, 0.005) << "the premise: blocks with steps";
  EXPECT_NEAR(got->meanBlockChange, want.meanChange, 0.6 / 2048);
  EXPECT_NEAR(got->meanBlockStep, want.meanStep, 0.6 / 2048);
  EXPECT_GT(want.meanStructure, 0.005) << "the premise: blocks with structure";
  EXPECT_NEAR(got->meanFrameStructure, want.meanStructure, 0.6 / 2048);
  EXPECT_NEAR(got->meanHistoryStructure, want.meanStructureBefore, 0.6 / 2048);
}

// The picture moves 16 px while the pose stays (an app's snap turn: it renders from its rig and submits the
// tracked head): the history's blocks are misplaced by 3.6 steps, and the frame is shown as a first frame
// is, to the bit. Without the test the box keeps much of the misplaced history (the premise).
TEST_F(CoreTest, SteadyStartsAfreshWhereThePoseDoesNotExplainTheFrame) {
  const uint32_t W = 64, H = 48;
  const HostImage before = wavesUnderChecker(W, H, 0.0f), after = wavesUnderChecker(W, H, 16.0f);
  const std::optional<HostImage> on = afterSettled(true, before, after),
                                 off = afterSettled(false, before, after);
  const std::optional<HostImage> fresh = firstFrame(after);
  ASSERT_TRUE(on && off && fresh) << "filter creation failed";
  EXPECT_GT(compare(*off, *fresh).meanAbs, 0.01f) << "the premise: the box keeps some of the old history";
  EXPECT_EQ(compare(*on, *fresh).maxAbs, 0.0f);
}

// What the pose explains stays filtered, to the bit of the filter without the test: the waves moved
// half a pixel (0.13 of a block's step), a fade of 2 % and one of 30 % (all the change one-signed: the gain
// explains it; the 30 % fade's blocks change by more than their steps),
// and a still picture under fresh noise every frame (noise differs between neighbours at least as much as
// from an average of it: at most 1 step).
TEST_F(CoreTest, SteadyKeepsTheHistoryWhereThePoseExplainsTheFrame) {
  const uint32_t W = 64, H = 48;
  const HostImage picture = wavesUnderChecker(W, H, 0.0f);
  HostImage faded = picture, deeplyFaded = picture;
  for (auto& p : faded.px) p = glm::vec4(glm::vec3(p) * 0.98f, p.a);
  for (auto& p : deeplyFaded.px) p = glm::vec4(glm::vec3(p) * 0.7f, p.a);
  struct Case {
    const char* name;
    HostImage after;
  };
  for (const Case& c : {Case{"half a pixel", wavesUnderChecker(W, H, 0.5f)}, Case{"a fade", toHalf(faded)},
                        Case{"a deep fade (round 33: its structure kept, relit)", toHalf(deeplyFaded)}}) {
    const std::optional<HostImage> on = afterSettled(true, picture, c.after);
    const std::optional<HostImage> off = afterSettled(false, picture, c.after);
    const std::optional<HostImage> fresh = firstFrame(c.after);
    ASSERT_TRUE(on && off && fresh) << "filter creation failed";
    EXPECT_GT(compare(*off, *fresh).meanAbs, 0.0005f) << c.name << ": the premise, a history that counts";
    EXPECT_EQ(compare(*on, *off).maxAbs, 0.0f) << c.name;
  }
  std::array<HostImage, 2> outs;
  for (bool on : {false, true}) {
    auto f = makeFilter("steady", steadyCut(on));
    ASSERT_TRUE(f) << "filter creation failed";
    Rig rig(W, H);
    for (uint32_t k = 0; k < 12; ++k) {
      const HostImage frame = toHalf(pattern(W, H, 100 + k, 0.1f));
      outs[on] = rig.run(*f, Frame{{frame, frame}, {eye(0, 0), eye(0, 0)}}, 1)[0];
    }
  }
  EXPECT_EQ(compare(outs[0], outs[1]).maxAbs, 0.0f) << "fresh noise";
}

// Round 33: a cut to a flat view darkens every sample alike, as a fade does, but loses the structure the
// history had (held-out seed 77: a snap that took a noisy picture out of view). The settled history of a
// noisy picture (the noise estimate on, as in the default, which widens the box), then a flat frame darker
// than all of it: shown as a first frame is, to the bit. Without the test the widened box keeps some of the
// old picture (the premise).
TEST_F(CoreTest, SteadyStartsAfreshWhereAFadeLosesThePicturesStructure) {
  const uint32_t W = 64, H = 48;
  HostImage flat(W, H);
  for (auto& p : flat.px) p = glm::vec4(0.2f, 0.2f, 0.2f, 1.0f);
  flat = toHalf(flat);
  std::array<std::optional<HostImage>, 2> outs;
  for (bool on : {false, true}) {
    Params p = *applyMethodName("steady");
    p.steadyUnexplainedFrameResets = on;
    auto f = makeFilter("steady", p);
    ASSERT_TRUE(f) << "filter creation failed";
    Rig rig(W, H);
    const HostImage picture = pattern(W, H, 7);
    for (uint32_t k = 0; k < 16; ++k) {
      const HostImage grainy = pattern(W, H, 200 + k, 0.05f);  // the picture plus fresh grain
      HostImage noisy = picture;
      for (size_t i = 0; i < noisy.px.size(); ++i) {  // the picture's half, lifted above the flat view
        const glm::vec3 grain = glm::vec3(grainy.px[i]) - glm::vec3(picture.px[i]);
        noisy.px[i] = glm::vec4(glm::vec3(0.35f) + 0.5f * glm::vec3(picture.px[i]) + grain, 1.0f);
      }
      noisy = toHalf(noisy);
      rig.run(*f, Frame{{noisy, noisy}, {eye(0, 0), eye(0, 0)}}, 1);
    }
    outs[on] = rig.run(*f, Frame{{flat, flat}, {eye(0, 0), eye(0, 0)}}, 1)[0];
  }
  auto fresh = makeFilter("steady", *applyMethodName("steady"));
  ASSERT_TRUE(fresh) << "filter creation failed";
  Rig rig(W, H);
  const HostImage first = rig.run(*fresh, Frame{{flat, flat}, {eye(0, 0), eye(0, 0)}}, 1)[0];
  EXPECT_GT(compare(*outs[false], first).maxAbs, 0.0f)
      << "the premise: the widened box keeps some of the picture";
  EXPECT_EQ(compare(*outs[true], first).maxAbs, 0.0f);
}
