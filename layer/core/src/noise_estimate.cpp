#include "noise_estimate.h"

#include <algorithm>
#include <cmath>

namespace steadyxr::core::detail {

namespace {
// The median of |N(0, 1)|: Phi^-1(3/4).
constexpr double kMedianAbsNormal = 0.6744897501960817;
// Var(Y) / Var(a channel) for Y = R/4 + G/2 + B/4 of independent channels of equal variance.
constexpr double kLumaShareOfChannelVariance = 1.0 / 16.0 + 1.0 / 4.0 + 1.0 / 16.0;
}  // namespace

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

void NoiseTracker::add(const uint32_t* bins, float footprintK, bool residualOverTime) {
  const std::optional<float> spatial = noiseVarianceFromHistogram(bins);
  if (!residualOverTime) {
    if (spatial) variance_ = spatial;
    return;
  }
  const std::optional<float> residual = noiseVarianceFromHistogram(bins + kNoiseBins);
  if (!spatial || !residual) {  // no history yet (a reset, a first frame): start the window again
    residualFrames_ = 0;
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
}

}  // namespace steadyxr::core::detail
