#include "noise_estimate.h"

#include <algorithm>
#include <cmath>

namespace steadyxr::core::detail {

namespace {
// The median of |N(0, 1)|: Phi^-1(3/4).
constexpr double kMedianAbsNormal = 0.6744897501960817;
constexpr double kPi = 3.14159265358979323846;
// Var(Y) / Var(a channel) for Y = R/4 + G/2 + B/4 of independent channels of equal variance.
constexpr double kLumaShareOfChannelVariance = 1.0 / 16.0 + 1.0 / 4.0 + 1.0 / 16.0;
}  // namespace

std::array<uint32_t, kNoiseRecordWords> mergeNoiseCopies(const uint32_t* buffer) {
  std::array<uint32_t, kNoiseRecordWords> record{};
  for (uint32_t copy = 0; copy < kNoiseCopies; ++copy)
    for (uint32_t w = 0; w < kNoiseRecordWords; ++w)
      record[w] += buffer[copy * kNoiseCopyStrideWords + w];  // modulo 2^32: the signed sum stays exact
  return record;
}

uint32_t noiseBin(float absDetail) {
  if (!(absDetail >= std::exp2(kNoiseLowestLog2))) return 0;  // also NaN
  const double t = kNoiseBinsPerOctave * (std::log2(static_cast<double>(absDetail)) - kNoiseLowestLog2);
  return static_cast<uint32_t>(std::min(t + 1.0, static_cast<double>(kNoiseBins - 1)));
}

std::optional<float> noiseVarianceFromHistogram(const uint32_t* bins) {
  // Bin 0 (no diagonal detail at all: unrendered or masked, saturated, flat and clean, an edge along
  // an axis) is left out: noise varies every pixel it reaches.
  uint64_t total = 0;
  for (uint32_t b = 1; b < kNoiseBins; ++b) total += bins[b];
  if (total == 0) return std::nullopt;
  const double half = 0.5 * static_cast<double>(total);
  double below = 0.0;
  uint32_t b = 1;
  while (b + 1 < kNoiseBins && below + bins[b] < half) below += bins[b++];
  const double within = (half - below) / static_cast<double>(bins[b]);
  const double log2Median = kNoiseLowestLog2 + (static_cast<double>(b - 1) + within) / kNoiseBinsPerOctave;
  const double sigmaLuma = std::exp2(log2Median) / kMedianAbsNormal;
  return static_cast<float>(sigmaLuma * sigmaLuma / kLumaShareOfChannelVariance);
}

float footprintDetailGain(float footprintK) {
  const double k = footprintK;
  const double normSquared =
      2.0 * k * k + 2.0 * (1.0 - 4.0 * k) * (1.0 - 4.0 * k) + (6.0 * k - 2.0) * (6.0 * k - 2.0);
  return static_cast<float>(normSquared / 6.0);
}

int residualMeanSide(const uint32_t* bins) {
  uint64_t samples = 0;
  for (uint32_t b = 0; b < kNoiseBins; ++b) samples += bins[kNoiseBins + b];
  const uint32_t* sums = bins + kNoiseHistograms * kNoiseBins;
  const double sum = static_cast<int32_t>(sums[0]), magnitude = sums[1];
  if (samples < 2 || magnitude <= 0.0) return 0;
  const double n = static_cast<double>(samples);
  const double sigma = std::sqrt(kPi / 2.0) * magnitude / n;  // in the sums' units
  if (std::abs(sum / n) < kChangeTestStandardErrors * sigma / std::sqrt(n)) return 0;
  return sum > 0.0 ? 1 : -1;
}

void NoiseTracker::add(const uint32_t* bins, float footprintK, bool residualOverTime, bool changeTest) {
  const std::optional<float> spatial = noiseVarianceFromHistogram(bins);
  frameDetail_ = spatial;
  if (!residualOverTime) {
    if (spatial) variance_ = spatial;
    return;
  }
  const std::optional<float> residual = noiseVarianceFromHistogram(bins + kNoiseBins);
  if (!spatial || !residual) {  // no history yet (a reset, a first frame): start the window again
    residualFrames_ = 0;
    meanSideRun_ = 0;
    variance_.reset();
    return;
  }
  const float gain = footprintDetailGain(footprintK);
  std::copy_backward(residual_.begin(), residual_.end() - 1, residual_.end());
  residual_[0] = *residual / (gain * gain);
  residualFrames_ = std::min(residualFrames_ + 1, kResidualWindowFrames);
  // While the window fills (the frames after a start), the residuals it has: a history of one frame
  // holds that frame's noise too, so it caps noise less, never more.
  variance_ = std::min(*spatial, *std::min_element(residual_.begin(), residual_.begin() + residualFrames_));
  // A fade's lag is first order and on one side in every pixel; a box widened by the noise would let
  // it through at up to the noise's own size, `none`'s error. While the picture changes as a whole
  // the box is the default's (round 15).
  const int side = residualMeanSide(bins);
  const int run = side == 0 ? 0 : (side > 0) == (meanSideRun_ > 0) ? meanSideRun_ + side : side;
  meanSideRun_ = std::clamp(run, -kChangeRunFrames, kChangeRunFrames);  // a fade may last for ever
  if (changeTest && std::abs(meanSideRun_) >= kChangeRunFrames) variance_ = 0.0f;
}

}  // namespace steadyxr::core::detail
