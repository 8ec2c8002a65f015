// Image-quality metrics of the evaluation (seed 002, 003, 004), on CPU over read-back images.
// All inputs are display-encoded (sRGB) values in [0, 1].
#pragma once

#include "camera.h"
#include "image.h"

#include <cstdint>

namespace steadyxr::eval {

// Seed 003 Eq. 6, one term: mean over pixels of the RGB Euclidean distance between two
// consecutive frames. MTCD of a sequence is the mean of this over consecutive pairs.
double temporalColorDifference(const Image& previous, const Image& current);

// Mean squared error over pixels and channels; RMSE = sqrt(mse).
double meanSquaredError(const Image& a, const Image& b);
double rmse(const Image& a, const Image& b);

// SSIM (Wang et al. 2004) on Rec. 601 luma, 11x11 Gaussian window (sigma 1.5), C1 = (0.01)^2,
// C2 = (0.03)^2 for a dynamic range of 1; mean over the pixels whose window lies inside.
double ssim(const Image& a, const Image& b);

// Seed 004: a pixel is an error pixel when any channel differs by more than `threshold`.
int64_t errorPixels(const Image& a, const Image& b, float threshold);

// Seed 002's reprojected stereo difference: every left-eye pixel is carried into the right eye
// through the left depth, rejected when the right eye's depth there disagrees (occlusion), and
// the squared RGB difference to the bilinear right-eye sample is averaged (per channel).
struct StereoDifference {
  double meanSquared = 0.0;
  double validFraction = 0.0;
};
StereoDifference stereoDifference(const Image& left, const DepthMap& leftDepth, const EyeCamera& leftCam,
                                  const Image& right, const DepthMap& rightDepth, const EyeCamera& rightCam,
                                  float relativeDepthTolerance = 0.02f);

}  // namespace steadyxr::eval
