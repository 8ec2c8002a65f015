// Scoring one frame of one method against the ground truth: the running sums of a (scenario,
// method), the frame's references (ground truth, display-stage poses) and the per-frame figures.
#pragma once

#include "camera.h"
#include "image.h"
#include "suite.h"

#include <array>
#include <vector>

namespace steadyxr::eval {

// Running sums of one (scenario, variant).
struct Accum {
  double sqErr = 0, sqN = 0, ssimSum = 0, ssimN = 0;
  double mtcdSum = 0, mtcdN = 0, tempErrSum = 0, tempErrN = 0, mtcdDispSum = 0, mtcdDispN = 0;
  double sqErrDisp = 0, sqDispN = 0, errPxDisp = 0, errPxDispN = 0;
  double stereoSum = 0, stereoN = 0, stereoErrSum = 0, stereoErrN = 0;
  double gpuTemporal = 0, gpuStereo = 0, gpuOther = 0, gpuN = 0;
  double timedWallMs = 0, timedGpuMs = 0;  // medians of the back-to-back timing frames
  double cpuUs = 0, cpuN = 0, renderMs = 0, renderN = 0;
  std::vector<double> frameRmse;  // per frame, both eyes (ghosting per frame)
  std::array<Image, 2> prev, prevDisplay;
};

inline double safeDiv(double a, double b) {
  return b > 0 ? a / b : 0.0;
}

// What every method's output of one frame is scored against.
struct FrameTruth {
  std::array<Image, 2> gt, prevGt;  // prevGt is empty on a case's first frame
  std::array<EyeCamera, 2> cams;    // the unjittered eye cameras (output grid)
  std::array<DepthMap, 2> depth;    // their 1-sample depth (stereo correspondences)
  std::vector<std::array<EyeCamera, 2>> dispCams;
  std::vector<std::array<Image, 2>> dispGt;
};

struct FrameScore {
  double rmse = 0, ssim = 0, mtcd = -1, tempErr = -1, mtcdDisp = -1, rmseDisp = 0, stereoDiff = 0,
         stereoErr = 0;
};

// Scores one frame's output (both eyes) into the method's running sums.
FrameScore scoreFrame(Accum& a, const std::array<Image, 2>& out, const FrameTruth& ft, const Options& o);

}  // namespace steadyxr::eval
