// Dynamic resolution (`steadyxr-eval --render-sizes F1,F2,...`): the app renders each frame at the next
// fraction of the eye size in turn, inside the same images, as an app that scales its render size to hold
// its frame rate. Every method runs three ways over the same cases: at the fixed full size, at the changing
// sizes keeping its history (the filter reprojects it from last frame's size), and at the changing sizes
// dropping it at each change (what the filter did before round 37). Each is scored against `none` at the
// same sizes, frame by frame, against the ground truth at the frame's own size.
#pragma once

#include "suite.h"

namespace steadyxr::eval {

// Returns the process exit code (0 on success); writes render_sizes.csv into o.outDir.
int runRenderSizeStudy(const Options& o);

}  // namespace steadyxr::eval
