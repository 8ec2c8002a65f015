// Seed 004's study of late-stage reprojection: how many pixels of the app's left-eye image differ
// from the truth when extrapolated k display frames ahead by timewarp or by depth-image warping.
#pragma once

#include "camera.h"
#include "eye_rig.h"
#include "renderer.h"
#include "scene.h"
#include "suite.h"

#include <functional>
#include <ostream>
#include <string>

namespace steadyxr::eval {

// One app frame of a case, as the study needs it.
struct WarpStudyFrame {
  const std::string& label;
  int index;  // frame number in the case
  double t;   // app time of the frame, seconds
  double dt;  // app frame interval, seconds
  float headSpeed;
  float objectSpeed;
  const RenderedView& leftView;  // the app's 1-sample left-eye render of the frame
  const EyeCamera& leftCamera;
};

// Appends the frame's rows to warp_errors.csv (`csv`). Renders into eye 0's 1-sample target, so
// it runs after the filters have read it. False with *error set when a render fails.
bool writeWarpStudy(SceneRenderer& renderer, const Scene& scene, const Options& o,
                    const std::function<HeadPose(double)>& headAt, const WarpStudyFrame& frame,
                    std::ostream& csv, std::string* error);

}  // namespace steadyxr::eval
