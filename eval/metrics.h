// Image-quality metrics of the evaluation (seed 002, 003, 004), on CPU over read-back images.
// All inputs are display-encoded (sRGB) values in [0, 1].
#pragma once

#include "camera.h"
#include "image.h"

#include <cstdint>
#include <vector>

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

// Temporal error against ground truth (issue 13): mean over pixels of the RGB Euclidean norm of
// (O_k - O_{k-1}) - (G_k - G_{k-1}). Zero for a perfect sequence; unlike MTCD it punishes an
// output that lags the head (changes less than the truth does) as much as one that shimmers.
// Equals MTCD when the ground truth does not change. Same [0, 1] scale as the inputs.
double temporalErrorVsTruth(const Image& previousOut, const Image& out, const Image& previousTruth,
                            const Image& truth);

// The image as an 8-bit target holds it: every channel rounded to the nearest of the 256 levels
// (the eval reads every method's output back from an R8G8B8A8 image; the ground truth is float).
// The temporal error of the rounded truth against the truth is what a perfect 8-bit output
// scores: the rounding flips a level wherever the truth crosses a level boundary, however small
// its change, so where the truth hardly moves (sub-pixel tremor at a low pixel density) this
// floor is a large part of `none`'s temporal error.
Image roundTo8Bit(const Image& img);

// Per-pixel stereo error (issue 13): over the left-eye pixels the right eye also sees (by the
// ground truth's depth, as stereoDifference), D(x) = L(x) - R(q(x)) is the reprojected left-right
// difference; the error is the mean RGB Euclidean norm of D_method - D_truth. Zero when the
// method's eyes differ exactly as the truth's do; unlike a difference of image-wide averages it
// cannot be met by errors that cancel, and it does not blow up when the truth's difference is 0.
double stereoErrorPerPixel(const Image& leftOut, const Image& rightOut, const Image& leftTruth,
                           const Image& rightTruth, const DepthMap& leftDepth, const EyeCamera& leftCam,
                           const DepthMap& rightDepth, const EyeCamera& rightCam,
                           float relativeDepthTolerance = 0.02f);

// Frames where the head motion changes (a stop, a start, a saccade), detected from the head speed
// per frame: frame k (k >= 1) when |h_k - h_{k-1}| >= thresholdDegPerSec.
std::vector<int> detectMotionChanges(const std::vector<double>& headSpeedDegPerSec,
                                     double thresholdDegPerSec);

// The RMS error of rounding to 8 bits (step 1/255, error uniform over +-half a step: 1/(255 sqrt 12)):
// a per-frame RMSE below it is as exact as an 8-bit image can be.
inline constexpr double kEightBitRmseFloor = 1.0 / (255.0 * 3.4641016151377544);

// Ghosting per frame of one method against `none` over the same frames of one case, none's RMSE
// taken as at least kEightBitRmseFloor.
struct Ghosting {
  double worstRatio = 0.0;  // max over frames of rmse_method / max(rmse_none, floor)
  int worstFrame = -1;
  // Max over the motion changes of the frames from the change until the method's RMSE is back at
  // or below none's (0: never above); a change it never recovers from counts the frames to the end.
  int recoveryFrames = 0;
  bool recovered = true;  // every change recovered within the run
};
Ghosting ghostingPerFrame(const std::vector<double>& methodRmse, const std::vector<double>& noneRmse,
                          const std::vector<int>& changeFrames);

// Percentile p in [0, 1] of the values (nearest rank); 0 for none.
double percentile(std::vector<double> values, double p);

}  // namespace steadyxr::eval
