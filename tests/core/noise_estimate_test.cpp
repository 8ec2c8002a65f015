// The noise estimate's host half (layer/core/src/noise_estimate.h): the histogram's bins and the
// robust scale of Donoho and Johnstone (1994), sigma = median |d| / Phi^-1(3/4), checked on samples
// drawn from a known normal distribution (the constants below are worked out here, not read from
// the code).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "noise_estimate.h"

using namespace steadyxr::core::detail;

namespace {

// A luma of standard deviation sigmaLuma from independent channels of variance v: sigmaLuma^2 =
// (1/16 + 1/4 + 1/16) v, so v = sigmaLuma^2 * 8 / 3.
float channelVariance(double sigmaLuma) {
  return static_cast<float>(sigmaLuma * sigmaLuma * 8.0 / 3.0);
}

std::array<uint32_t, kNoiseBins> histogramOf(double sigmaLuma, int samples, int flatSamples, uint32_t seed) {
  std::array<uint32_t, kNoiseBins> bins{};
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, sigmaLuma);
  for (int i = 0; i < samples; ++i) ++bins[noiseBin(static_cast<float>(std::abs(normal(rng))))];
  bins[0] += static_cast<uint32_t>(flatSamples);  // exactly flat 3x3s: no variation to measure
  return bins;
}

}  // namespace

TEST(NoiseEstimate, BinsAreQuarterOctavesAboveTwoToTheMinusSixteen) {
  EXPECT_EQ(noiseBin(0.0f), 0u);
  EXPECT_EQ(noiseBin(std::nanf("")), 0u);
  EXPECT_EQ(noiseBin(std::exp2(-16.5f)), 0u);
  EXPECT_EQ(noiseBin(std::exp2(-16.0f)), 1u);  // the first quarter octave
  EXPECT_EQ(noiseBin(std::exp2(-15.8f)), 1u);
  EXPECT_EQ(noiseBin(std::exp2(-15.7f)), 2u);  // 0.3 octaves up: the second
  EXPECT_EQ(noiseBin(std::exp2(-6.0f)), 41u);  // 10 octaves: 40 quarters, plus bin 0
  EXPECT_EQ(noiseBin(0.9f), kNoiseBins - 1);   // the last bin is open above
  EXPECT_EQ(noiseBin(1e6f), kNoiseBins - 1);
}

TEST(NoiseEstimate, MedianOfAbsoluteDetailGivesTheNoiseVariance) {
  for (const double sigmaLuma : {0.002, 0.01, 0.05}) {
    const auto bins = histogramOf(sigmaLuma, 20000, 0, 7);
    const auto v = noiseVarianceFromHistogram(bins.data());
    ASSERT_TRUE(v.has_value());
    EXPECT_NEAR(*v / channelVariance(sigmaLuma), 1.0, 0.04) << sigmaLuma;
  }
}

TEST(NoiseEstimate, FlatSamplesAreLeftOutAndAnEmptyHistogramGivesNone) {
  // A picture shown on a black surround, or behind a lens mask: 3x3s with no variation at all.
  const auto bins = histogramOf(0.01, 5000, 20000, 11);
  const auto v = noiseVarianceFromHistogram(bins.data());
  ASSERT_TRUE(v.has_value());
  EXPECT_NEAR(*v / channelVariance(0.01), 1.0, 0.06);
  std::array<uint32_t, kNoiseBins> flatOnly{};
  flatOnly[0] = 1000;
  EXPECT_FALSE(noiseVarianceFromHistogram(flatOnly.data()).has_value());
  const std::array<uint32_t, kNoiseBins> empty{};
  EXPECT_FALSE(noiseVarianceFromHistogram(empty.data()).has_value());
}

namespace {

// The (1, -2, 1) x (1, -2, 1) detail of noise passed through the footprint [k, 1 - 2k, k]^2, written
// from the definition: the 5x5 kernel as the 2-D convolution of the two 3x3 kernels, whose norm
// against the plain detail's (6) is the standard deviation ratio for white noise.
double detailOfFilteredNoiseRatio(double k) {
  const double detail1d[3] = {1.0, -2.0, 1.0}, footprint1d[3] = {k, 1.0 - 2.0 * k, k};
  double kernel[5][5] = {};
  for (int dy = 0; dy < 3; ++dy)
    for (int dx = 0; dx < 3; ++dx)
      for (int fy = 0; fy < 3; ++fy)
        for (int fx = 0; fx < 3; ++fx)
          kernel[dy + fy][dx + fx] += detail1d[dy] * detail1d[dx] * footprint1d[fy] * footprint1d[fx];
  double normSquared = 0.0;
  for (const auto& row : kernel)
    for (double w : row) normSquared += w * w;
  return std::sqrt(normSquared) / 6.0;
}

// Both histograms of a frame: the frame's own detail of luma standard deviation sigmaSpatial, the
// residual's of sigmaResidual.
std::array<uint32_t, 2 * kNoiseBins> framesHistograms(double sigmaSpatial, double sigmaResidual,
                                                      uint32_t seed) {
  std::array<uint32_t, 2 * kNoiseBins> bins{};
  const auto spatial = histogramOf(sigmaSpatial, 20000, 0, seed);
  std::copy(spatial.begin(), spatial.end(), bins.begin());
  if (sigmaResidual > 0.0) {
    const auto residual = histogramOf(sigmaResidual, 20000, 0, seed + 1000);
    std::copy(residual.begin(), residual.end(), bins.begin() + kNoiseBins);
  }
  return bins;
}

constexpr float kFootprint = 1.0f / 24.0f;

}  // namespace

TEST(NoiseEstimate, FootprintDetailGainIsTheFilteredNoisesDetail) {
  for (const double k : {0.0, 1.0 / 24.0, 1.0 / 16.0})
    EXPECT_NEAR(footprintDetailGain(static_cast<float>(k)), detailOfFilteredNoiseRatio(k), 1e-6) << k;
  EXPECT_NEAR(footprintDetailGain(kFootprint), 0.7425, 1e-4);
}

// Round 14: noise fills the residual as the frame (through the footprint: gain x sigma, and more
// where the history holds some noise of its own), so the estimate is the noise's from the first frame
// with a residual on.
TEST(NoiseEstimate, TrackerGivesTheNoiseFromTheFirstResidual) {
  const double sigma = 0.01, gain = detailOfFilteredNoiseRatio(kFootprint);
  NoiseTracker tracker;
  const auto noHistory = framesHistograms(sigma, 0.0, 1);
  tracker.add(noHistory.data(), kFootprint, true);
  EXPECT_FALSE(tracker.variance().has_value());
  for (uint32_t frame = 0; frame < 6; ++frame) {
    const auto bins = framesHistograms(sigma, 1.05 * gain * sigma, frame);
    tracker.add(bins.data(), kFootprint, true);
    ASSERT_TRUE(tracker.variance().has_value()) << frame;
    EXPECT_NEAR(*tracker.variance() / channelVariance(sigma), 1.0, 0.05) << frame;
  }
}

// Fine detail that holds: the frame's own detail is large, the residual small; the smallest residual
// of the last four frames, so one frame with a change (a video frame) does not count.
TEST(NoiseEstimate, TrackerTakesTheSmallestResidualOfFourFrames) {
  const double detail = 0.05, residual = 0.001, change = 0.02;
  const double gain = detailOfFilteredNoiseRatio(kFootprint);
  NoiseTracker tracker;
  for (uint32_t frame = 0; frame < 8; ++frame) {
    const auto bins = framesHistograms(detail, frame == 5 ? change : residual, frame);
    tracker.add(bins.data(), kFootprint, true);
    ASSERT_TRUE(tracker.variance().has_value()) << frame;
    EXPECT_NEAR(*tracker.variance() / channelVariance(residual / gain), 1.0, 0.05) << frame;
  }
  // A change in each of four frames in a row (content at the display rate) does count.
  for (uint32_t frame = 0; frame < 4; ++frame) {
    const auto bins = framesHistograms(detail, change, 30 + frame);
    tracker.add(bins.data(), kFootprint, true);
  }
  ASSERT_TRUE(tracker.variance().has_value());
  EXPECT_GT(*tracker.variance(), 0.5 * channelVariance(change / gain));
  // Round 13's: the frame's own detail alone.
  NoiseTracker spatialOnly;
  const auto bins = framesHistograms(detail, residual, 1);
  spatialOnly.add(bins.data(), kFootprint, false);
  ASSERT_TRUE(spatialOnly.variance().has_value());
  EXPECT_NEAR(*spatialOnly.variance() / channelVariance(detail), 1.0, 0.05);
}

// A frame without a residual (no confirmed history: a reset, a cut) starts the window again: the
// residuals from before it no longer count.
TEST(NoiseEstimate, TrackerStartsAgainWithoutAResidual) {
  const double gain = detailOfFilteredNoiseRatio(kFootprint);
  NoiseTracker tracker;
  for (uint32_t frame = 0; frame < 4; ++frame) {
    const auto bins = framesHistograms(0.05, 0.001, frame);
    tracker.add(bins.data(), kFootprint, true);
  }
  ASSERT_TRUE(tracker.variance().has_value());
  const auto noHistory = framesHistograms(0.05, 0.0, 9);
  tracker.add(noHistory.data(), kFootprint, true);
  EXPECT_FALSE(tracker.variance().has_value());
  const auto bins = framesHistograms(0.05, 0.01, 20);
  tracker.add(bins.data(), kFootprint, true);
  ASSERT_TRUE(tracker.variance().has_value());
  EXPECT_NEAR(*tracker.variance() / channelVariance(0.01 / gain), 1.0, 0.05);
}
