// Seed 004's reprojection study: timewarp and forward depth-image warping against fresh renders.
#include "warp_study.h"

#include "metrics.h"
#include "results.h"
#include "warp.h"

namespace steadyxr::eval {

bool writeWarpStudy(SceneRenderer& renderer, const Scene& scene, const Options& o,
                    const std::function<HeadPose(double)>& headAt, const WarpStudyFrame& frame,
                    std::ostream& csv, std::string* error) {
  const size_t nPix = size_t(o.width) * o.height;
  const double t = frame.t, dt = frame.dt;
  // Extrapolate k display frames ahead by (a) rotational timewarp and (b) forward depth-image
  // warping with per-pixel motion, and count pixels that differ from the frame rendered at that time.
  for (int k = 1; k <= o.warpSteps; ++k) {
    const double td = t + k / o.displayHz;
    const auto dc = eyeCameras(headAt(td), o.width, o.height, o.eyeRig());
    DrawList draws = scene.drawsAt(td);
    draws.noiseSeed = uint32_t(frame.index * 2 + 1);
    if (o.noise > 0.0f) draws.noiseAmplitude = o.noise;
    RenderedView truth;
    if (!renderer.renderBase(0, dc[0], draws, &truth, nullptr, error)) return false;
    const Image tw = rotationalTimewarp(frame.leftView.color, frame.leftCamera, dc[0]);
    const MotionField motion = [&](const glm::vec3& p) { return scene.motion(p, t, dt); };
    const Image fw = forwardDepthWarp(frame.leftView.color, frame.leftView.depth, frame.leftCamera, dc[0],
                                      motion, float((k / o.displayHz) / dt));
    for (int mode = 0; mode < 2; ++mode) {
      const int64_t e = errorPixels(mode == 0 ? tw : fw, truth.color, o.errorThreshold);
      csv << csvEscape(frame.label) << ',' << frame.index << ',' << k << ','
          << fmt(1000.0 * k / o.displayHz, 5) << ',' << fmt(frame.headSpeed, 5) << ','
          << fmt(frame.objectSpeed, 5) << ',' << (mode == 0 ? "timewarp" : "depthwarp") << ',' << e << ','
          << fmt(double(e) / double(nPix), 6) << '\n';
    }
  }
  return true;
}

}  // namespace steadyxr::eval
