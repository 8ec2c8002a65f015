// Per-frame accuracy of a method's output: RMSE/SSIM, temporal and stereo metrics, and the display
// stage (the runtime's timewarp until the next app frame).
#include "frame_score.h"

#include "metrics.h"
#include "warp.h"

#include <cmath>

namespace steadyxr::eval {

// Scores one frame's output (both eyes) into the method's running sums.
FrameScore scoreFrame(Accum& a, const std::array<Image, 2>& out, const FrameTruth& ft, const Options& o) {
  FrameScore s;
  const double nPix = double(out[0].width) * out[0].height;
  const int ratio = int(ft.dispCams.size());
  double frameSq = 0, frameSqDisp = 0;
  for (int eye = 0; eye < 2; ++eye) {
    const double mse = meanSquaredError(out[eye], ft.gt[eye]);
    frameSq += mse / 2;
    a.sqErr += mse * nPix * 3;
    a.sqN += nPix * 3;
    const double ss = ssim(out[eye], ft.gt[eye]);
    s.ssim += ss / 2;
    a.ssimSum += ss;
    a.ssimN += 1;
    if (!a.prev[eye].empty()) {
      const double m = 255.0 * temporalColorDifference(a.prev[eye], out[eye]);
      s.mtcd = (s.mtcd < 0 ? 0 : s.mtcd) + m / 2;
      a.mtcdSum += m;
      a.mtcdN += 1;
      const double te = 255.0 * temporalErrorVsTruth(a.prev[eye], out[eye], ft.prevGt[eye], ft.gt[eye]);
      s.tempErr = (s.tempErr < 0 ? 0 : s.tempErr) + te / 2;
      a.tempErrSum += te;
      a.tempErrN += 1;
    }
    // Display stage (a): the runtime's rotational timewarp of this frame until the next one.
    for (int k = 0; k < ratio; ++k) {
      const Image shown = k == 0 ? out[eye] : rotationalTimewarp(out[eye], ft.cams[eye], ft.dispCams[k][eye]);
      const double dmse = meanSquaredError(shown, ft.dispGt[k][eye]);
      frameSqDisp += dmse / (2 * ratio);
      a.sqErrDisp += dmse;
      a.sqDispN += 1;
      a.errPxDisp += double(errorPixels(shown, ft.dispGt[k][eye], o.errorThreshold)) / nPix;
      a.errPxDispN += 1;
      if (!a.prevDisplay[eye].empty()) {
        const double m = 255.0 * temporalColorDifference(a.prevDisplay[eye], shown);
        s.mtcdDisp = (s.mtcdDisp < 0 ? 0 : s.mtcdDisp) + m / (2 * ratio);
        a.mtcdDispSum += m;
        a.mtcdDispN += 1;
      }
      a.prevDisplay[eye] = shown;
    }
  }
  s.rmse = std::sqrt(frameSq);
  s.rmseDisp = std::sqrt(frameSqDisp);
  a.frameRmse.push_back(s.rmse);
  s.stereoDiff =
      stereoDifference(out[0], ft.depth[0], ft.cams[0], out[1], ft.depth[1], ft.cams[1]).meanSquared;
  a.stereoSum += s.stereoDiff;
  a.stereoN += 1;
  s.stereoErr = 255.0 * stereoErrorPerPixel(out[0], out[1], ft.gt[0], ft.gt[1], ft.depth[0], ft.cams[0],
                                            ft.depth[1], ft.cams[1]);
  a.stereoErrSum += s.stereoErr;
  a.stereoErrN += 1;
  a.prev = out;
  return s;
}

}  // namespace steadyxr::eval
