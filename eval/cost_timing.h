// A method's cost: its filter run on one frame back to back, after warm-up, timed by the wall clock
// (submit to idle) and by the filter's GPU timestamps.
#pragma once

#include "renderer.h"

#include "steadyxr/core/filter.h"

#include <string>

namespace steadyxr::eval {

struct BackToBackTimes {
  double wallMs = 0;  // median, submit to idle
  double gpuMs = 0;   // median of the filter's timestamps (0 without them)
};

// Submits `frame` to `filter` (outputs: the renderer's output images) back to back; false with
// *error set when a submit fails.
bool timeBackToBack(core::Filter& filter, const core::StereoFrame& frame, SceneRenderer& renderer,
                    BackToBackTimes* out, std::string* error);

}  // namespace steadyxr::eval
