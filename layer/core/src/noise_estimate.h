// The render's noise level, from the histogram the temporal pass fills (shaders/temporal.comp,
// recordNoiseSample). Donoho and Johnstone's robust scale estimate ("Ideal spatial adaptation by
// wavelet shrinkage", Biometrika 1994): sigma = median |d| / 0.6745 over the finest diagonal detail
// coefficients d, which noise fills everywhere and a picture only at its finest detail. Here d is
// the luma's x^2 y^2 contrast of a 3x3, divided by its norm (6), so that d has the luma noise's
// standard deviation.
//
// Round 14: the same detail of a second quantity, the residual between this frame's footprint
// estimate and the reprojected history, fills a second histogram. Noise is new in every frame, so it
// fills both alike (the residual more, by the history's own noise); a picture's fine detail is in the
// history too and leaves only what the clip keeps between them. Content that changes in place fills
// the residual most in the frame where it changes. The estimate is the smaller of the frame's own and
// the smallest residual one of the last few frames (the history's lag after a change still counts).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

namespace steadyxr::core::detail {

// Bin 0: |d| < 2^kNoiseLowestLog2 (a flat 3x3 of 8-bit input gives exactly 0); bin b >= 1:
// |d| in [2^(lowest + (b - 1) / perOctave), 2^(lowest + b / perOctave)), the last bin open above.
// The same constants as temporal.comp's.
constexpr uint32_t kNoiseBins = 64;
constexpr float kNoiseBinsPerOctave = 4.0f;
constexpr float kNoiseLowestLog2 = -16.0f;
// Two histograms: [0, kNoiseBins) the frame's own detail, [kNoiseBins, 2 kNoiseBins) the residual's.
constexpr uint32_t kNoiseHistograms = 2;
constexpr uint32_t kNoiseHistogramBytes = kNoiseHistograms * kNoiseBins * sizeof(uint32_t);
// The residual estimates the smallest is taken over. Content at a lower rate than the display (24-60
// fps video at 72-120 Hz) changes in at most 2 of any 3 consecutive frames; 4 frames hold one more
// frame without a change. Noise is new in every frame.
constexpr size_t kResidualWindowFrames = 4;

// The bin of one |d| (what the shader computes), for the tests.
uint32_t noiseBin(float absDetail);
// The noise variance per linear RGB channel: (median |d| / 0.6745)^2 is the luma's (3/8 of a
// channel's, for independent channels: Y = R/4 + G/2 + B/4). 0 for a median in bin 0, none for an
// empty histogram. The median is interpolated within its bin on the log scale.
std::optional<float> noiseVarianceFromHistogram(const uint32_t* bins);

// The standard deviation of the detail of noise passed through steady's footprint filter
// [k, 1 - 2k, k]^2, relative to the detail of the raw noise: per axis (1, -2, 1) * (k, 1 - 2k, k) =
// (k, 1 - 4k, 6k - 2, 1 - 4k, k), whose norm squared over (1, -2, 1)'s (6) is the variance ratio of
// one axis; the two axes multiply, the standard deviation is its square root. 0.7425 at k = 1/24.
float footprintDetailGain(float footprintK);

// The render's noise estimate over frames: each finished frame adds its two histograms.
class NoiseTracker {
 public:
  // residualOverTime = false: round 13's estimate, the frame's own detail alone.
  void add(const uint32_t* bins, float footprintK, bool residualOverTime);
  void reset() { *this = NoiseTracker{}; }
  // The variance per linear RGB channel; none until a frame (with residualOverTime: a frame with a
  // history) gave an estimate.
  std::optional<float> variance() const { return variance_; }

 private:
  std::array<float, kResidualWindowFrames> residual_{};
  size_t residualFrames_ = 0;  // residual estimates in a row, up to the window
  std::optional<float> variance_;
};

}  // namespace steadyxr::core::detail
