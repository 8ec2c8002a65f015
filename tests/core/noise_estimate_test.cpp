// The noise estimate's host half (layer/core/src/noise_estimate.h): the histogram's bins and the
// robust scale of Donoho and Johnstone (1994), sigma = median |d| / Phi^-1(3/4), checked on samples
// drawn from a known normal distribution (the constants below are worked out here, not read from
// the code).
#include <gtest/gtest.h>

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
