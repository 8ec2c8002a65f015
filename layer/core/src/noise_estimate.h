// The render's noise level, from the histogram the temporal pass fills (shaders/temporal.comp,
// recordNoiseSample). Donoho and Johnstone's robust scale estimate ("Ideal spatial adaptation by
// wavelet shrinkage", Biometrika 1994): sigma = median |d| / 0.6745 over the finest diagonal detail
// coefficients d, which noise fills everywhere and a picture only at its finest detail. Here d is
// the luma's x^2 y^2 contrast of a 3x3, divided by its norm (6), so that d has the luma noise's
// standard deviation.
#pragma once

#include <cstdint>
#include <optional>

namespace steadyxr::core::detail {

// Bin 0: |d| < 2^kNoiseLowestLog2 (a flat 3x3 of 8-bit input gives exactly 0); bin b >= 1:
// |d| in [2^(lowest + (b - 1) / perOctave), 2^(lowest + b / perOctave)), the last bin open above.
// The same constants as temporal.comp's.
constexpr uint32_t kNoiseBins = 64;
constexpr float kNoiseBinsPerOctave = 4.0f;
constexpr float kNoiseLowestLog2 = -16.0f;
constexpr uint32_t kNoiseHistogramBytes = kNoiseBins * sizeof(uint32_t);

// The bin of one |d| (what the shader computes), for the tests.
uint32_t noiseBin(float absDetail);
// The noise variance per linear RGB channel: (median |d| / 0.6745)^2 is the luma's (3/8 of a
// channel's, for independent channels: Y = R/4 + G/2 + B/4). 0 for a median in bin 0, none for an
// empty histogram. The median is interpolated within its bin on the log scale.
std::optional<float> noiseVarianceFromHistogram(const uint32_t* bins);

}  // namespace steadyxr::core::detail
