// The noise estimate's host half (layer/core/src/noise_estimate.h): the histogram's bins and the
// robust scale of Donoho and Johnstone (1994), sigma = median |d| / Phi^-1(3/4), checked on samples
// drawn from a known normal distribution (the constants below are worked out here, not read from
// the code).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "filter_passes.h"
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

constexpr size_t kBufferWords = kNoiseRecordWords;  // one frame's record, as the tracker reads it
constexpr int kResidualSamples = 20000;

// The residual's two sums over kResidualSamples luma residuals drawn from N(mean, sigma), in the
// shader's fixed point (temporal.comp, addResidualSums: 2^-11 units, clamped to +-1/2, the signed sum
// in two's complement).
void fillResidualSums(uint32_t* sums, double mean, double sigma, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(mean, sigma);
  int64_t sum = 0, magnitude = 0;
  for (int i = 0; i < kResidualSamples; ++i) {
    const auto scaled =
        static_cast<int64_t>(std::lround(std::clamp(normal(rng), -0.5, 0.5) * double(kResidualSumScale)));
    sum += scaled;
    magnitude += std::abs(scaled);
  }
  sums[0] = static_cast<uint32_t>(static_cast<int32_t>(sum));
  sums[1] = static_cast<uint32_t>(magnitude);
}

// Both histograms of a frame: the frame's own detail of luma standard deviation sigmaSpatial, the
// residual's of sigmaResidual; then the residual's sums, of mean residualMean (0: noise, which the
// history averages) and the same standard deviation.
std::array<uint32_t, kBufferWords> framesHistograms(double sigmaSpatial, double sigmaResidual, uint32_t seed,
                                                    double residualMean = 0.0) {
  std::array<uint32_t, kBufferWords> bins{};
  const auto spatial = histogramOf(sigmaSpatial, 20000, 0, seed);
  std::copy(spatial.begin(), spatial.end(), bins.begin());
  if (sigmaResidual > 0.0) {
    const auto residual = histogramOf(sigmaResidual, kResidualSamples, 0, seed + 1000);
    std::copy(residual.begin(), residual.end(), bins.begin() + kNoiseBins);
    fillResidualSums(bins.data() + kNoiseHistograms * kNoiseBins, residualMean, sigmaResidual, seed + 2000);
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
  tracker.add(noHistory.data(), kFootprint, true, true);
  EXPECT_FALSE(tracker.variance().has_value());
  for (uint32_t frame = 0; frame < 6; ++frame) {
    const auto bins = framesHistograms(sigma, 1.05 * gain * sigma, frame);
    tracker.add(bins.data(), kFootprint, true, true);
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
    tracker.add(bins.data(), kFootprint, true, true);
    ASSERT_TRUE(tracker.variance().has_value()) << frame;
    EXPECT_NEAR(*tracker.variance() / channelVariance(residual / gain), 1.0, 0.05) << frame;
  }
  // A change in each of four frames in a row (content at the display rate) does count.
  for (uint32_t frame = 0; frame < 4; ++frame) {
    const auto bins = framesHistograms(detail, change, 30 + frame);
    tracker.add(bins.data(), kFootprint, true, true);
  }
  ASSERT_TRUE(tracker.variance().has_value());
  EXPECT_GT(*tracker.variance(), 0.5 * channelVariance(change / gain));
  // Round 13's: the frame's own detail alone.
  NoiseTracker spatialOnly;
  const auto bins = framesHistograms(detail, residual, 1);
  spatialOnly.add(bins.data(), kFootprint, false, false);
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
    tracker.add(bins.data(), kFootprint, true, true);
  }
  ASSERT_TRUE(tracker.variance().has_value());
  const auto noHistory = framesHistograms(0.05, 0.0, 9);
  tracker.add(noHistory.data(), kFootprint, true, true);
  EXPECT_FALSE(tracker.variance().has_value());
  const auto bins = framesHistograms(0.05, 0.01, 20);
  tracker.add(bins.data(), kFootprint, true, true);
  ASSERT_TRUE(tracker.variance().has_value());
  EXPECT_NEAR(*tracker.variance() / channelVariance(0.01 / gain), 1.0, 0.05);
}

// Round 15: the residual's mean over the frame against its standard error sigma / sqrt(n), sigma from
// the mean magnitude as a normal's (E|r| = sigma sqrt(2 / pi)); off 0 at 4 standard errors or more,
// on either side.
TEST(NoiseEstimate, ResidualMeanSideFromFourStandardErrors) {
  const double sigma = 0.01, standardError = sigma / std::sqrt(double(kResidualSamples));
  for (uint32_t seed = 0; seed < 20; ++seed) {
    EXPECT_EQ(residualMeanSide(framesHistograms(0.02, sigma, seed).data()), 0) << "noise, seed " << seed;
    for (const int side : {1, -1})  // 8 standard errors: the sample's own scatter cannot hide it
      EXPECT_EQ(residualMeanSide(framesHistograms(0.02, sigma, seed, side * 8.0 * standardError).data()),
                side)
          << "8 standard errors, seed " << seed;
  }
  // The threshold itself, on sums written out: n samples of mean magnitude sigma sqrt(2 / pi) (2^-11
  // units), the signed sum at 3.9 and 4.1 standard errors.
  auto bins = framesHistograms(0.02, sigma, 1);
  const double n = kResidualSamples, magnitudeUnits = sigma * std::sqrt(2.0 / 3.14159265358979) * 2048.0 * n;
  const double standardErrorUnits = sigma * 2048.0 * n / std::sqrt(n);  // of the sum
  uint32_t* sums = bins.data() + kNoiseHistograms * kNoiseBins;
  sums[1] = static_cast<uint32_t>(std::lround(magnitudeUnits));
  for (const auto& [z, side] :
       {std::pair{3.9, 0}, std::pair{4.1, 1}, std::pair{-3.9, 0}, std::pair{-4.1, -1}}) {
    sums[0] = static_cast<uint32_t>(static_cast<int32_t>(std::lround(z * standardErrorUnits)));
    EXPECT_EQ(residualMeanSide(bins.data()), side) << z << " standard errors";
  }
  // A fade: every pixel's residual of one sign.
  EXPECT_EQ(residualMeanSide(framesHistograms(0.02, 0.001, 1, -0.01).data()), -1);
  // No residual at all (no history): nothing to test.
  EXPECT_EQ(residualMeanSide(framesHistograms(0.02, 0.0, 1).data()), 0);
}

// The estimate is 0 from the second frame in a row whose residual's mean lies on one side (a fade),
// and the noise's again from the first frame whose residual averages out. A mean that changes side
// every frame (tremor over a ramp) leaves it alone. Without the test (round 14's) it stays.
TEST(NoiseEstimate, TrackerGivesNoNoiseWhileTheResidualKeepsItsSide) {
  const double sigma = 0.01, gain = detailOfFilteredNoiseRatio(kFootprint), off = 0.5 * gain * sigma;
  for (const bool changeTest : {true, false}) {
    NoiseTracker tracker;
    for (uint32_t frame = 0; frame < 14; ++frame) {
      const bool fading = frame >= 4 && frame < 8, toAndFro = frame >= 10;
      const double mean = fading ? -off : toAndFro ? (frame % 2 == 0 ? off : -off) : 0.0;
      const auto bins = framesHistograms(sigma, gain * sigma, frame, mean);
      tracker.add(bins.data(), kFootprint, true, changeTest);
      ASSERT_TRUE(tracker.variance().has_value()) << frame;
      if (fading && frame > 4 && changeTest)
        EXPECT_EQ(*tracker.variance(), 0.0f) << frame;
      else
        EXPECT_NEAR(*tracker.variance() / channelVariance(sigma), 1.0, 0.05) << frame << " " << changeTest;
    }
  }
}

// The GPU adds to kNoiseCopies copies of the record, each on cache lines of its own; the host's
// record is their sum, word by word, the signed sum's negative parts included (modulo 2^32).
TEST(NoiseEstimate, CopiesAddUpToOneRecord) {
  EXPECT_GE(kNoiseCopyStrideWords, kNoiseRecordWords);
  EXPECT_EQ(kNoiseCopyStrideWords % 16, 0u);  // 64-byte lines
  std::vector<uint32_t> buffer(kNoiseBufferBytes / sizeof(uint32_t), 0u);
  const uint32_t signedSum = kNoiseHistograms * kNoiseBins;
  for (uint32_t copy = 0; copy < kNoiseCopies; ++copy) {
    uint32_t* record = buffer.data() + copy * kNoiseCopyStrideWords;
    record[3] = copy + 1;               // a bin of the frame's histogram
    record[kNoiseBins + 7] = 2 * copy;  // a bin of the residual's
    record[signedSum] = static_cast<uint32_t>(copy % 2 == 0 ? -100 : 40);
  }
  const auto record = mergeNoiseCopies(buffer.data());
  EXPECT_EQ(record[3], 36u);                                 // 1 + 2 + ... + 8
  EXPECT_EQ(record[kNoiseBins + 7], 56u);                    // 2 (0 + 1 + ... + 7)
  EXPECT_EQ(static_cast<int32_t>(record[signedSum]), -240);  // 4 x -100 + 4 x 40
  EXPECT_EQ(record[4], 0u);
}

// The probe's blocks (filter_passes.h, rounds 17 and 28): one sample per block of side B at its centre,
// the smallest B from 4 up that holds at most 1024 samples an eye. The figures are counted here from
// that rule: 128x128 holds 32 x 32 samples of 4 px blocks, exactly the budget (so every evaluated eye,
// 96-128 px, keeps 4 px blocks); 256x256 holds 64 x 64 with 4 px, 43 x 43 with 6, 36 x 36 with 7 and
// 32 x 32 with 8; 1024x1024 33 x 33 with 31 and 32 x 32 with 32; 1832x1920 (a headset's eye) 31 x 33 =
// 1023 with 59 px and 32 x 33 with 58.
TEST(GainProbe, BlocksKeepAnEyeWithinItsSampleBudget) {
  EXPECT_EQ(probeBlockPx(96, 96), 4);
  EXPECT_EQ(probeBlockPx(128, 128), 4);
  EXPECT_EQ(probeBlockPx(256, 256), 8);
  EXPECT_EQ(probeBlockPx(1024, 1024), 32);
  EXPECT_EQ(probeBlockPx(1832, 1920), 59);
  EXPECT_EQ(probeSamples(1832, 1920, 59), 31 * 33);
  EXPECT_EQ(probeSamples(1832, 1920, 58), 32 * 33);
  // A partial block counts where its centre lies inside the eye: 1045 = 130 * 8 + 5 holds 131.
  EXPECT_EQ(probeSamples(1045, 8, 8), 131);
  EXPECT_EQ(probeSamples(1044, 8, 8), 130);
  EXPECT_EQ(probeSamples(1, 1, 4), 0);
  // Within the budget and no coarser than it needs, over many sizes.
  for (int32_t w = 1; w <= 5000; w += 37) {
    for (int32_t h = 1; h <= 5000; h += 41) {
      const int32_t b = probeBlockPx(w, h);
      ASSERT_LE(probeSamples(w, h, b), 1024) << w << "x" << h;
      if (b > 4) {
        ASSERT_GT(probeSamples(w, h, b - 1), 1024) << w << "x" << h;
      }
    }
  }
}
