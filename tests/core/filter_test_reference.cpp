// The filter's passes on real Vulkan (lavapipe, validation on) against their independent CPU
// references (reference.h, written from the seeds): temporal, steady, fxaa, stereo.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/packing.hpp>
#include <glm/gtc/quaternion.hpp>
#include <random>
#include <string>
#include <vector>

#include "filter_test_rig.h"
#include "reference.h"
#include "steadyxr/core/jitter.h"

using namespace steadyxr;
using namespace steadyxr::core;
using namespace steadyxr::test;

class TemporalReference : public CoreTest, public ::testing::WithParamInterface<std::string> {};

TEST_P(TemporalReference, MatchesCpuReference) {
  const std::string method = GetParam();
  const uint32_t W = 64, H = 64;
  Params p = *applyMethodName(method);
  if (method == "hmtaa2") {
    p = *applyMethodName("hmtaa");
    p.sampleCount = 2;
  }
  if (method == "hybrid-catmull" || method == "taa-catmull") {
    p = *applyMethodName(method.substr(0, method.find('-')));
    p.historyFilter = HistoryFilter::CatmullRom;
  }
  const bool withDepth = method == "taa-depth";
  if (withDepth) p = *applyMethodName("taa");
  std::string err;
  auto f = Filter::create(*gCtx, p, &err);
  ASSERT_TRUE(f) << err;
  Rig rig(W, H);
  Frame f1, f2;
  f1.color = {pattern(W, H, 7), pattern(W, H, 8)};
  f1.views = {eye(0.0f, 0.0f), eye(0.0f, 0.0f, {0.064f, 0, 0})};
  f2.color = {pattern(W, H, 9, 0.05f), pattern(W, H, 10, 0.05f)};
  f2.views = {eye(1.3f, -0.7f, {0.01f, 0.0f, 0.02f}), eye(1.3f, -0.7f, {0.074f, 0.0f, 0.02f})};
  f2.headSpeed = 6.0f;
  if (withDepth) {
    for (auto* fr : {&f1, &f2})
      for (int e = 0; e < 2; ++e) {
        fr->depth[e] = HostImage(W, H);
        for (uint32_t y = 0; y < H; ++y)
          for (uint32_t x = 0; x < W; ++x) {
            const float z = x < W / 2 ? 0.5f : 3.0f;  // metres: a near half and a far half
            fr->depth[e].at(x, y).r = (1.0f / z - 1.0f / 0.1f) / (1.0f / 100.0f - 1.0f / 0.1f);
          }
      }
  }
  const auto out1 = rig.run(*f, f1);
  for (int e = 0; e < 2; ++e) EXPECT_LE(compare(out1[e], f1.color[e]).maxAbs, 1e-3f) << "first frame = input";
  const auto out2 = rig.run(*f, f2);
  for (int e = 0; e < 2; ++e) {
    const auto method_ = p.temporal;
    const HostImage want =
        test::temporalRef(method_, p, toHalf(f2.color[e]), toHalf(f1.color[e]), true, f1.views[e],
                          f2.views[e], f2.headSpeed, withDepth ? &f2.depth[e] : nullptr, 0.1f, 100.0f);
    const Diff d = compare(out2[e], want);
    // Tolerance: GPU bilinear weights have 8 sub-texel bits (<= 1/256 of a neighbour difference),
    // RGBA16F storage (~1e-3). Few pixels sit exactly on a clip/fallback decision boundary.
    EXPECT_LE(d.meanAbs, 2e-3f) << method << " eye " << e;
    EXPECT_LE(d.maxAbs, 0.05f) << method << " eye " << e;
    // The filter did something: the output is not just the current frame.
    EXPECT_GT(compare(out2[e], f2.color[e]).meanAbs, 5e-3f) << method;
  }
}

INSTANTIATE_TEST_SUITE_P(Passes, TemporalReference,
                         ::testing::Values("taa", "hmtaa", "hmtaa2", "vtaa", "hybrid", "taa-depth",
                                           "hybrid-catmull", "taa-catmull"),
                         [](const auto& pinfo) {
                           std::string s = pinfo.param;
                           for (auto& c : s)
                             if (c == '-') c = '_';
                           return s;
                         });

namespace {
// Linear light rounded to the nearest 8-bit sRGB code (IEC 61966-2-1 encode, then decode).
HostImage toSrgb8(HostImage img) {
  for (auto& px : img.px)
    for (int ch = 0; ch < 3; ++ch) px[ch] = float(srgbDecode(std::round(srgbEncode(px[ch]) * 255.0) / 255.0));
  return img;
}
}  // namespace

// The steady method against its CPU reference, chained over four frames: the sample count
// builds up in the history's alpha, a patch that moves makes clips lower it, the head rotates and
// translates by sub-pixel amounts, and the frames carry noise.
class SteadyReference : public CoreTest, public ::testing::WithParamInterface<std::string> {};

TEST_P(SteadyReference, MatchesCpuReference) {
  const std::string variant = GetParam();
  const uint32_t W = 64, H = 64;
  Params p = *applyMethodName("steady");
  // The noise allowance is the host's estimate from the frames (round 15: on by default; checked in
  // steady_noise_test.cpp); here the pass is given it: none (a clean render), or told (noisetold).
  p.steadyNoiseEstimate = false;
  p.steadyGainCompensation = false;  // round 16's frame gain: steady_gain_test.cpp
  // Round 26: the blur guard traded against that noise (the default), under the default motion and a sway;
  // noisetold keeps the guard alone (steadyBlurNoiseTrade off, the default before round 26).
  const bool trade = variant == "noisetrade" || variant == "noisetradesway";
  if (variant == "noisetold" || trade) p.steadyNoiseVariance = 0.05f * 0.05f / 3.0f;  // the frames' own noise
  if (variant == "noisetold") p.steadyBlurNoiseTrade = false;
  if (variant == "catmull") p.historyFilter = HistoryFilter::CatmullRom;
  if (variant == "linearfootprint") p.steadyFootprintEncoded = false;
  if (variant == "summedblur" || variant == "swaysummed") p.steadyHistoryBlurPerAxis = false;
  // A sway: the head turns about 0.5 px a frame along x only, where the blur guard per axis and the
  // summed one disagree most (the blurrier axis counted twice against it counted once).
  const bool sway = variant == "sway" || variant == "swaysummed" || variant == "noisetradesway";
  const float yawStep = sway ? 0.8f : 0.35f, pitchStep = sway ? 0.0f : -0.2f;
  const glm::vec3 moveStep = sway ? glm::vec3(0.0f) : glm::vec3(0.004f, 0.0f, 0.002f);
  if (variant == "interpolated") p.steadyInterpolated = true;
  if (variant == "rejectnoblur") {
    p.steadyClipRejects = true;
    p.steadyBlurBudgetPx2 = 0.0f;
  }
  if (variant == "constant") p.steadyConfidence = false;
  if (variant == "clipholdscurrent") p.steadyClipHoldsCurrent = true;
  // The curvature bound is on by default: these two keep the path without it checked.
  if (variant == "nocurvbox" || variant == "nocurvboxjitter") p.steadyClipCurvature = false;
  // Round 7: the one-sided curvature box is the default; these two keep the symmetric box checked.
  if (variant == "nocurvcentred" || variant == "nocurvcentredjitter") p.steadyClipCurvatureCentred = false;
  // Round 10's option (off by default): the one-sided box only where the history lags on one side.
  if (variant == "curvgate") p.steadyClipCurvatureCentredGated = true;
  if (variant == "wideclip") {  // steady's clip box is its own, not taa's
    p.steadyClipGamma = 2.0f;
    p.taaClipGamma = 0.5f;
  }
  const bool withDepth = variant == "depth";
  // 8-bit sRGB input, where the clip's floor is half an sRGB step (Params::steadyClipQuantSrgb);
  // the other variants feed RGBA16F, where it is half a linear step.
  const bool srgbInput = variant == "srgbinput" || variant == "srgbinputlinearfloor";
  if (variant == "srgbinputlinearfloor") p.steadyClipQuantSrgb = false;
  // Jittered input: the layer's Halton(2,3) offsets, one per frame (and one frame unjittered).
  const bool jittered = variant == "jitter" || variant == "jitterraw" || variant == "nocurvboxjitter" ||
                        variant == "nocurvcentredjitter";
  p.jitteredInput = jittered;
  // The raw jittered sample (Karis 2014, not recentred): its 3x3 is not about the pixel centre, so
  // the one-sided box, whose interval is about the centre, discards the history there; the
  // variant checks the raw path with round 6's symmetric box.
  if (variant == "jitterraw") {
    p.steadyJitterRecentred = false;
    p.steadyClipCurvatureCentred = false;
  }
  auto f = makeFilter("steady", p);
  ASSERT_TRUE(f);
  Rig rig(W, H, srgbInput ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_R16G16B16A16_SFLOAT);
  std::array<HostImage, 2> hist;
  std::array<RefView, 2> prev;
  // The noise trade acts where the blur guard binds, once the count's alpha is near its floor: 12 frames.
  const int frames = trade ? 12 : 4;
  for (int k = 0; k < frames; ++k) {
    Frame fr;
    fr.color = {pattern(W, H, 20 + k, 0.05f), pattern(W, H, 30 + k, 0.05f)};
    for (auto& img : fr.color)  // a patch moving 3 px a frame over the static pattern
      for (uint32_t y = 40; y < 50; ++y)
        for (uint32_t x = 8u + 3u * uint32_t(k); x < 18u + 3u * uint32_t(k); ++x)
          img.at(x, y) = glm::vec4(1.0f, 0.2f, 0.6f, 1.0f);
    const float fk = float(k);
    if (jittered && k != 2) fr.jitter = {haltonJitterPx(uint32_t(k) + 3), haltonJitterPx(uint32_t(k) + 4)};
    fr.views = {eye(yawStep * fk, pitchStep * fk, moveStep * fk),
                eye(yawStep * fk, pitchStep * fk, glm::vec3(0.064f, 0.0f, 0.0f) + moveStep * fk)};
    for (int e = 0; e < 2 && withDepth; ++e) {
      fr.depth[e] = HostImage(W, H);
      for (uint32_t y = 0; y < H; ++y)
        for (uint32_t x = 0; x < W; ++x) {
          const float z = x < W / 2 ? 0.5f : 3.0f;  // metres: a near half and a far half
          fr.depth[e].at(x, y).r = (1.0f / z - 1.0f / 0.1f) / (1.0f / 100.0f - 1.0f / 0.1f);
        }
    }
    if (srgbInput)
      for (auto& img : fr.color) img = toSrgb8(img);  // what the pass reads back from the image
    const auto out = rig.run(*f, fr);
    for (int e = 0; e < 2; ++e) {
      const HostImage want =
          toHalf(test::steadyRef(p, toHalf(fr.color[e]), hist[e], k > 0, prev[e], fr.views[e],
                                 withDepth ? &fr.depth[e] : nullptr, 0.1f, 100.0f, fr.jitter[e], srgbInput));
      const Diff d = compare(out[e], want);
      // Tolerance as in TemporalReference (8 sub-texel bits of GPU bilinear weights, half
      // precision), over a chain of frames; few pixels sit on a clip decision boundary.
      // The noise trade's variants are held closer: on lavapipe they match to 2.4e-4 on average and 2e-3 at
      // most; its alpha's exponent 1/3, no reach bound, or the noise left in c'' each put 5e-4 to 9e-4 on
      // average and 0.023 to 0.049 at most (round 26, planted).
      EXPECT_LE(d.meanAbs, trade ? 4e-4f : 2e-3f) << variant << " frame " << k << " eye " << e;
      EXPECT_LE(d.maxAbs, trade ? 0.01f : 0.05f) << variant << " frame " << k << " eye " << e;
      if (k > 0) {
        EXPECT_GT(compare(out[e], fr.color[e]).meanAbs, 5e-3f) << variant << ": the history is used";
      }
      hist[e] = want;
      prev[e] = fr.views[e];
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Variants, SteadyReference,
                         ::testing::Values("default", "catmull", "linearfootprint", "summedblur", "sway",
                                           "swaysummed", "interpolated", "rejectnoblur", "constant", "depth",
                                           "wideclip", "jitter", "jitterraw", "clipholdscurrent", "nocurvbox",
                                           "nocurvboxjitter", "nocurvcentred", "nocurvcentredjitter",
                                           "curvgate", "srgbinput", "srgbinputlinearfloor", "noisetold",
                                           "noisetrade", "noisetradesway"));

namespace {
// Pixels of `a` farther than `tolerance` from `b` in any channel.
int pixelsOff(const HostImage& a, const HostImage& b, float tolerance) {
  int n = 0;
  for (size_t i = 0; i < a.px.size(); ++i)
    n += glm::any(glm::greaterThan(glm::abs(glm::vec3(a.px[i]) - glm::vec3(b.px[i])), glm::vec3(tolerance)));
  return n;
}

// A straight step edge through the image centre at `slopeDeg` from horizontal (dark below-left,
// bright above-right), sampled at pixel centres (one sample per pixel, as a rasteriser without
// MSAA draws it) or as the 16x16 box average of each pixel (the ground truth).
HostImage steppedEdge(uint32_t w, uint32_t h, double slopeDeg, int samplesPerAxis) {
  const glm::dvec2 centre(w / 2.0 + 0.31, h / 2.0 + 0.17);  // off the pixel grid's symmetry
  const glm::dvec2 normal(-std::sin(slopeDeg * kDeg), std::cos(slopeDeg * kDeg));
  const glm::vec3 dark(0.05f, 0.08f, 0.1f), bright(0.9f, 0.7f, 0.5f);
  HostImage img(w, h);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      int inside = 0;
      for (int j = 0; j < samplesPerAxis; ++j)
        for (int i = 0; i < samplesPerAxis; ++i) {
          const glm::dvec2 q(x + (i + 0.5) / samplesPerAxis, y + (j + 0.5) / samplesPerAxis);
          inside += glm::dot(q - centre, normal) < 0.0;  // image y grows downwards
        }
      const float f = float(inside) / float(samplesPerAxis * samplesPerAxis);
      img.at(x, y) = glm::vec4(glm::mix(dark, bright, f), 1.0f);
    }
  return img;
}
}  // namespace

TEST_F(CoreTest, FxaaMatchesCpuReference) {
  const uint32_t W = 64, H = 64;
  HostImage img(W, H);
  for (uint32_t y = 0; y < H; ++y)
    for (uint32_t x = 0; x < W; ++x) {
      // hard-edged shapes: a tilted edge, a circle, thin lines
      const bool a = float(y) > 0.35f * float(x) + 10.0f;
      const bool b = (x - 40) * (x - 40) + (y - 20) * (y - 20) < 120;
      const bool c = (x + 2 * y) % 11 == 0;
      // A little per-pixel texture: without it the repeated exact values make FXAA's comparisons
      // exact ties (e.g. edgeHorz == edgeVert beside the thin lines), which device and CPU
      // arithmetic may break either way.
      const float t = 0.03f * float((x * 7919u + y * 104729u) % 61u) / 60.0f;
      img.at(x, y) =
          glm::vec4((a ? 0.9f : 0.1f) - t, (b ? 0.8f : 0.2f) + t, (c ? 1.0f : 0.0f) + 0.5f * t, 1.0f);
    }
  auto f = makeFilter("fxaa");
  Rig rig(W, H);
  Frame fr;
  fr.color = {img, img};
  fr.views = {eye(0, 0), eye(0, 0)};
  const auto out = rig.run(*f, fr);
  const HostImage want = test::fxaaRef(toHalf(img));
  // Pixel by pixel: within the half-float output and the sampler's 8-bit bilinear weights
  // (1/256 of a step of at most 1), everywhere but a handful of pixels where a comparison of
  // equal float values (a luma tie) may go either way on the device.
  const int changed = pixelsOff(want, toHalf(img), 0.01f);
  const int off = pixelsOff(out[0], want, 0.01f);
  std::printf("fxaa vs the CPU reference: %d of %d pixels off by more than 0.01 (%d pixels changed)\n", off,
              int(W * H), changed);
  EXPECT_GT(changed, 300);  // the reference itself smoothed the edges
  EXPECT_LE(off, 4);
  EXPECT_LE(compare(out[0], want).meanAbs, 5e-4f);

  // A long, nearly horizontal edge (38 px steps): the search runs to its last, unsampled step.
  const HostImage longEdge = steppedEdge(W, H, 1.5, 1);
  fr.color = {longEdge, longEdge};
  const auto outLong = rig.run(*f, fr);
  const HostImage wantLong = test::fxaaRef(toHalf(longEdge));
  EXPECT_GT(pixelsOff(wantLong, toHalf(longEdge), 0.01f), 60);
  EXPECT_LE(pixelsOff(outLong[0], wantLong, 0.01f), 4);
  EXPECT_LE(compare(outLong[0], wantLong).meanAbs, 5e-4f);
}

TEST_F(CoreTest, FxaaLowersTheErrorOfASteppedEdgeAtEverySlope) {
  // FXAA against a supersampled edge: it must move every edge's pixels towards their coverage,
  // whatever the edge's direction (blending along the edge instead of across leaves the error).
  const uint32_t W = 64, H = 64;
  auto f = makeFilter("fxaa");
  Rig rig(W, H);
  for (double slope : {5.0, 20.0, 45.0, 70.0, 88.0}) {
    const HostImage aliased = steppedEdge(W, H, slope, 1), truth = steppedEdge(W, H, slope, 16);
    Frame fr;
    fr.color = {aliased, aliased};
    fr.views = {eye(0, 0), eye(0, 0)};
    const auto out = rig.run(*f, fr);
    const float before = rmse(toHalf(aliased), truth), after = rmse(out[0], truth);
    const float cpu = rmse(test::fxaaRef(toHalf(aliased)), truth);
    std::printf(
        "step edge at %4.1f deg: RMSE vs 16x16 supersampled %.4f at 1 spp, %.4f after fxaa (CPU "
        "reference %.4f)\n",
        slope, before, after, cpu);
    // Near-horizontal and near-vertical edges are FXAA's best case (long spans: the end-of-edge
    // search gives each pixel its coverage); at 45 deg the steps are single pixels.
    const float bound = slope < 10.0 || slope > 80.0 ? 0.5f : 0.85f;
    EXPECT_LT(after, bound * before) << slope;
    EXPECT_LT(cpu, bound * before) << slope;
  }
}

// The rig's D32 depth (near 0.1, far 100) of a box at zBox over x0 < x < x1, y0 < y < y1
// (box = x0, y0, x1, y1) before a wall at zWall.
HostImage boxBeforeWall(uint32_t w, uint32_t h, glm::ivec4 box, float zBox, float zWall) {
  HostImage depth(w, h);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const bool inBox = int(x) > box.x && int(x)<box.z&& int(y)> box.y && int(y) < box.w;
      const float z = inBox ? zBox : zWall;
      depth.at(x, y).r = (1.0f / z - 1.0f / 0.1f) / (1.0f / 100.0f - 1.0f / 0.1f);
    }
  return depth;
}

class StereoReference : public CoreTest, public ::testing::WithParamInterface<bool> {};

TEST_P(StereoReference, MatchesCpuReference) {
  const bool withDepth = GetParam();
  const uint32_t W = 64, H = 48;
  Params base;
  base.stereoBetaMin = 0.5f;  // a visible blend; the default (0.9) takes at most 10 % of the other eye
  auto f = makeFilter("stereo", base);
  Rig rig(W, H);
  Frame fr;
  fr.views = {eye(0.5f, 0.0f, {-0.032f, 0, 0}), eye(0.5f, 0.0f, {0.032f, 0, 0})};
  fr.color = {pattern(W, H, 11, 0.08f), pattern(W, H, 12, 0.08f)};
  if (withDepth)
    fr.depth = {boxBeforeWall(W, H, {20, 10, 36, 30}, 0.4f, 2.0f),
                boxBeforeWall(W, H, {20, 10, 36, 30}, 0.4f, 2.0f)};
  const auto out = rig.run(*f, fr);
  const Params p = *applyMethodName("stereo", base);
  for (int e = 0; e < 2; ++e) {
    const int o = 1 - e;
    const HostImage want =
        test::stereoRef(p, toHalf(fr.color[e]), toHalf(fr.color[o]), fr.views[e], fr.views[o],
                        withDepth ? &fr.depth[e] : nullptr, withDepth ? &fr.depth[o] : nullptr, 0.1f, 100.0f);
    const Diff d = compare(out[e], want);
    EXPECT_LE(d.meanAbs, 3e-3f) << "eye " << e;
    EXPECT_LE(d.maxAbs, 0.08f) << "eye " << e;
    EXPECT_GT(compare(out[e], fr.color[e]).meanAbs, 5e-3f);
  }
}

INSTANTIATE_TEST_SUITE_P(Depth, StereoReference, ::testing::Bool());

// Two stereo frames one IPD apart: looking ahead, then turned by yawDeg and 0.3 deg of pitch;
// patterns seed..seed+3 (left and right of the first frame, then of the second).
std::array<Frame, 2> twoStereoFrames(uint32_t w, uint32_t h, uint32_t seed, float yawDeg) {
  std::array<Frame, 2> fr;
  fr[0].views = {eye(0.0f, 0.0f, {-0.032f, 0, 0}), eye(0.0f, 0.0f, {0.032f, 0, 0})};
  fr[0].color = {pattern(w, h, seed, 0.08f), pattern(w, h, seed + 1, 0.08f)};
  fr[1].views = {eye(yawDeg, 0.3f, {-0.032f, 0, 0}), eye(yawDeg, 0.3f, {0.032f, 0, 0})};
  fr[1].color = {pattern(w, h, seed + 2, 0.08f), pattern(w, h, seed + 3, 0.08f)};
  return fr;
}

// Stereo after a temporal method (seed 002 §5.2: a post pass on both eyes' filtered frames)
// agrees with the stereo reference applied to the temporal result of this frame.
TEST_F(CoreTest, SeparateStereoPassAfterTemporalMatchesReference) {
  const uint32_t W = 48, H = 40;
  const Params p = *applyMethodName("hybrid+stereo");
  std::string err;
  auto f = Filter::create(*gCtx, p, &err);
  ASSERT_TRUE(f) << err;
  Rig rig(W, H);
  auto [f1, f2] = twoStereoFrames(W, H, 21, 0.8f);
  f2.headSpeed = 4.0f;
  rig.run(*f, f1);
  const auto out2 = rig.run(*f, f2);
  std::array<HostImage, 2> temporal;
  for (int e = 0; e < 2; ++e)
    temporal[e] = toHalf(test::temporalRef(p.temporal, p, toHalf(f2.color[e]), toHalf(f1.color[e]), true,
                                           f1.views[e], f2.views[e], f2.headSpeed));
  for (int e = 0; e < 2; ++e) {
    const HostImage want = test::stereoRef(p, temporal[e], temporal[1 - e], f2.views[e], f2.views[1 - e],
                                           nullptr, nullptr, 0.1f, 100.0f);
    const Diff d = compare(out2[e], want);
    EXPECT_LE(d.meanAbs, 3e-3f) << "eye " << e;
    EXPECT_LE(d.maxAbs, 0.08f) << "eye " << e;
  }
}

// Stereo after steady: beta from the eyes' error variances (each history's sample count, the
// bilinear tap, the disparity's spread without depth) and the other eye's tap corrected by this
// eye's curvature agree with the reference written from
// that equation, applied to steady's reference result of this frame. Two frames, so the counts
// and tap offsets differ across the image; a box before a wall with depth, a plane without.
class SteadyStereoReference : public CoreTest, public ::testing::WithParamInterface<bool> {};

TEST_P(SteadyStereoReference, MatchesCpuReference) {
  const bool withDepth = GetParam();
  const uint32_t W = 48, H = 40;
  Params base;
  base.stereoFarDistanceM = 0.8f;  // without depth a near plane: a spread under a pixel blends
  const Params p = *applyMethodName("steady+stereo", base);
  ASSERT_TRUE(p.stereoInverseVariance);
  auto f = makeFilter("steady+stereo", base);
  auto alone = makeFilter("steady", base);
  Rig rig(W, H);
  auto [f1, f2] = twoStereoFrames(W, H, 31, 0.7f);
  if (withDepth) {
    const HostImage depth = boxBeforeWall(W, H, {16, 10, 30, 28}, 0.5f, 1.5f);
    f1.depth = f2.depth = {depth, depth};
  }
  rig.run(*f, f1);
  const auto out2 = rig.run(*f, f2);
  rig.run(*alone, f1);
  const auto steadyOnly = rig.run(*alone, f2);
  std::array<HostImage, 2> temporal;
  for (int e = 0; e < 2; ++e) {
    const HostImage first =
        toHalf(test::steadyRef(p, toHalf(f1.color[e]), HostImage(W, H), false, f1.views[e], f1.views[e],
                               withDepth ? &f1.depth[e] : nullptr));
    temporal[e] = toHalf(test::steadyRef(p, toHalf(f2.color[e]), first, true, f1.views[e], f2.views[e],
                                         withDepth ? &f2.depth[e] : nullptr));
  }
  for (int e = 0; e < 2; ++e) {
    const int o = 1 - e;
    const HostImage want = test::stereoRef(p, temporal[e], temporal[o], f2.views[e], f2.views[o],
                                           withDepth ? &f2.depth[e] : nullptr,
                                           withDepth ? &f2.depth[o] : nullptr, 0.1f, 100.0f, true);
    const Diff d = compare(out2[e], want);
    // Measured 3.5e-4 mean and 2e-3 at most (half-float histories); the tap's curvature term with
    // the wrong sign gives 1.7e-3 and 0.03.
    EXPECT_LE(d.meanAbs, 1e-3f) << "eye " << e;
    EXPECT_LE(d.maxAbs, 0.01f) << "eye " << e;
    EXPECT_GT(compare(out2[e], steadyOnly[e]).meanAbs, 2e-3f) << "eye " << e << ": the other eye blends in";
  }
}

INSTANTIATE_TEST_SUITE_P(Depth, SteadyStereoReference, ::testing::Bool());
