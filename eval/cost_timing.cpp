// Back-to-back timing of one method's filter on one frame (the cost columns of results.csv).
#include "cost_timing.h"

#include "metrics.h"

#include <chrono>
#include <vector>

namespace steadyxr::eval {

bool timeBackToBack(core::Filter& filter, const core::StereoFrame& frame, SceneRenderer& renderer,
                    BackToBackTimes* out, std::string* error) {
  // The first kWarm submits are not timed: lavapipe compiles shaders on first use.
  constexpr int kWarm = 2, kTimed = 6;
  std::vector<double> wall, gpu;
  for (int k = 0; k < kWarm + kTimed; ++k) {
    core::StereoOutput output;
    output.views = {renderer.output(0), renderer.output(1)};
    const auto c0 = std::chrono::steady_clock::now();
    const bool ok = filter.submit(frame, output, error);
    filter.waitIdle();
    const auto c1 = std::chrono::steady_clock::now();
    if (!ok) return false;
    if (k < kWarm) continue;
    wall.push_back(std::chrono::duration<double, std::milli>(c1 - c0).count());
    if (auto tm = filter.lastTimings()) gpu.push_back(tm->totalMs);
  }
  out->wallMs = percentile(wall, 0.5);
  out->gpuMs = percentile(gpu, 0.5);
  return true;
}

}  // namespace steadyxr::eval
