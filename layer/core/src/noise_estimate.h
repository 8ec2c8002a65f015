// The render's noise level, from the histogram the frame's probe fills (shaders/temporal.comp,
// probeFrame; the temporal pass until round 22). Donoho and Johnstone's robust scale estimate ("Ideal spatial
// adaptation by wavelet shrinkage", Biometrika 1994): sigma = median |d| / 0.6745 over the finest diagonal
// detail coefficients d, which noise fills everywhere and a picture only at its finest detail. Here d is the
// luma's x^2 y^2 contrast of a 3x3, divided by its norm (6), so that d has the luma noise's standard
// deviation.
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
// Round 15: after the histograms, the residual's luma summed over its samples, and its magnitude, in
// units of 1/kResidualSumScale (the first a signed sum in two's complement).
constexpr uint32_t kResidualSums = 2;
constexpr float kResidualSumScale = 2048.0f;
constexpr uint32_t kNoiseRecordWords = kNoiseHistograms * kNoiseBins + kResidualSums;  // one frame's record
// The GPU adds to kNoiseCopies copies of the record, each on cache lines of its own (a stride of
// kNoiseCopyStrideWords), by workgroup: on a CPU device (lavapipe) the cores then rarely add to the
// same line at once. The host adds the copies up (mergeNoiseCopies). Same as temporal.comp's.
constexpr uint32_t kNoiseCopies = 8;
constexpr uint32_t kNoiseCopyStrideWords = (kNoiseRecordWords + 15) / 16 * 16;  // 64-byte lines
constexpr uint32_t kNoiseBufferBytes = kNoiseCopies * kNoiseCopyStrideWords * sizeof(uint32_t);
// Round 16 (Params::steadyGainCompensation): the gain probe's record after the noise record's copies, on
// a line of its own (temporal.comp, probeFrame): the luma of the frame and of the reprojected history
// summed (units 1/kLumaSumScale), the magnitude of their difference (1/kResidualSumScale) and the
// samples. Both eyes' probes add to it; the temporal passes of the same frame read it, once per
// invocation. One copy since round 17: the probe adds its sums once per workgroup (round 22; once per 16
// samples before), so its adds seldom meet (round 16 kept kNoiseCopies copies, read by every invocation
// of the temporal passes).
// Round 31 (Params::steadyUnexplainedFrameResets): two more words, the magnitudes of the 4x4 blocks' luma
// change since the history and of their step to the next block, summed (1/kResidualSumScale). Round 33: two
// more, the structure of the frame's block and of the history's (the halves' differences, temporal.comp).
// Round 42: word 8, the head-locked switch's count (filter_head_locked.h, kHeadLockedCountWord).
constexpr uint32_t kGainRecordWords = 8;
constexpr uint32_t kGainCopyStrideWords = 16;  // one 64-byte line
constexpr float kLumaSumScale = 1024.0f;
constexpr uint32_t kGainBufferBytes = kGainCopyStrideWords * sizeof(uint32_t);
static_assert(kGainRecordWords <= kGainCopyStrideWords, "a copy of the gain record fits its line");
// The pass's storage buffer (binding 9): the noise record's copies, then the gain record's.
constexpr uint32_t kStorageBufferBytes = kNoiseBufferBytes + kGainBufferBytes;
// Round 15: the residual's mean is off 0 (a fade, a shift) when it lies this many standard errors
// from 0. Noise's residual has mean 0 wherever the history holds; 4 standard errors is a false
// alarm in about 1 frame of 16,000 (the normal's two tails), and the standard error is taken from the
// residual's mean magnitude as a normal's (sigma = sqrt(pi / 2) E|r|).
constexpr double kChangeTestStandardErrors = 4.0;
// The residual estimates the smallest is taken over. Content at a lower rate than the display (24-60
// fps video at 72-120 Hz) changes in at most 2 of any 3 consecutive frames; 4 frames hold one more
// frame without a change. Noise is new in every frame.
constexpr size_t kResidualWindowFrames = 4;

// The record of a frame: the sum of the GPU's kNoiseCopies copies in `buffer` (kNoiseBufferBytes).
std::array<uint32_t, kNoiseRecordWords> mergeNoiseCopies(const uint32_t* buffer);

// The bin of one |d| (what the shader computes), for the tests.
uint32_t noiseBin(float absDetail);
// The noise variance per linear RGB channel: (median |d| / 0.6745)^2 is the luma's (3/8 of a
// channel's, for independent channels: Y = R/4 + G/2 + B/4). The median is over bins 1 and up (bin 0,
// no diagonal detail at all, says nothing about noise) and interpolated within its bin on the log
// scale; none where no sample lies above bin 0 (an empty histogram, a picture of flat areas and
// axis-aligned edges), so never 0. (NoiseTracker's estimate is 0 only where the fade test sets it.)
std::optional<float> noiseVarianceFromHistogram(const uint32_t* bins);

// The standard deviation of the detail of noise passed through steady's footprint filter
// [k, 1 - 2k, k]^2, relative to the detail of the raw noise: per axis (1, -2, 1) * (k, 1 - 2k, k) =
// (k, 1 - 4k, 6k - 2, 1 - 4k, k), whose norm squared over (1, -2, 1)'s (6) is the variance ratio of
// one axis; the two axes multiply, the standard deviation is its square root. 0.7425 at k = 1/24.
float footprintDetailGain(float footprintK);

// The frames in a row whose residual's mean must lie on one side (round 15). A fade's lag keeps its
// side frame after frame; a shift of the picture leaves a mean too (tremor over a ramp or a banded
// gradient moves every band edge one way), but its side follows the head's to-and-fro. Two frames is
// the fewest that tell the two apart; measured, three let a fade over 1-px lines reach 1.42x `none`'s
// in a frame (held-out seed 32), where two hold it at 1.00x.
constexpr int kChangeRunFrames = 2;

// Round 15: the side of the residual's mean (the sums after the two histograms) where it lies
// kChangeTestStandardErrors standard errors or more from 0: +1 above, -1 below, 0 within.
int residualMeanSide(const uint32_t* bins);

// The render's noise estimate over frames: each finished frame adds its record (two histograms, two sums).
class NoiseTracker {
 public:
  // residualOverTime = false: round 13's estimate, the frame's own detail alone. changeTest: the
  // estimate is 0 while the residual's mean lies on one side of 0 in kChangeRunFrames frames in a
  // row: the picture changes as a whole (round 15).
  void add(const uint32_t* bins, float footprintK, bool residualOverTime, bool changeTest);
  void reset() { *this = NoiseTracker{}; }
  // The variance per linear RGB channel; none until a frame (with residualOverTime: a frame with a
  // history) gave an estimate.
  std::optional<float> variance() const { return variance_; }
  // Round 13's estimate of the newest frame added: its own finest detail (aliasing, texture and noise alike),
  // per linear RGB channel. Round 42's head-locked switch holds a match to what that detail can move a block.
  std::optional<float> frameDetailVariance() const { return frameDetail_; }

 private:
  std::array<float, kResidualWindowFrames> residual_{};
  size_t residualFrames_ = 0;  // residual estimates in a row, up to the window
  std::optional<float> variance_;
  std::optional<float> frameDetail_;
  int meanSideRun_ = 0;  // frames in a row whose residual's mean lay on one side; its sign the side
};

}  // namespace steadyxr::core::detail
