// Whether the filter's history may be carried into the frame about to be filtered. The history is
// the app's world as the layer last filtered it. It is dropped when the user has since seen
// something else: the app submitted frames without its world (no projection layer: a loading
// screen, a pause menu of quad layers, a session that stopped rendering). It is also dropped when
// the poses come in another space than the history's (the step between them is not known), and
// when more time has passed than any measurement covers. Dropping costs only the re-accumulation: the
// first frame after it is the app's own image.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

namespace steadyxr::layer {

class HistoryContinuity {
 public:
  // The longest gap between filtered frames across which the history is kept, in app periods. The
  // eval measures up to three periods missed in a row (steadyxr-eval --drop-frames,
  // eval/frame_clock.h: a step of four periods); the half period is for the rounding of predicted
  // display times.
  static constexpr double kLongestGapInPeriods = 4.5;
  // The app's period is the shortest of its recent steps between filtered frames (a missed frame
  // makes a step of two periods or more).
  static constexpr size_t kPeriodSteps = 8;

  // A frame without the app's world went to the runtime (before the first filtered frame there is
  // no history to drop: apps submit empty frames until they render).
  void frameWithoutWorld() { worldLeft_ = lastFilteredNs_.has_value(); }

  // Whether the frame at this display time, its poses in `poseSpace` (the projection layer's
  // XrSpace as a number), must start without the history.
  bool mustDrop(int64_t displayTimeNs, uint64_t poseSpace) const {
    if (worldLeft_) return true;
    if (!lastFilteredNs_) return false;  // the filter has no history yet
    if (poseSpace != lastSpace_) return true;
    const int64_t step = displayTimeNs - *lastFilteredNs_;
    if (step <= 0) return true;  // time went back: a new session, or an app's bad display time
    const int64_t period = recentPeriod();
    return period > 0 && static_cast<double>(step) > kLongestGapInPeriods * static_cast<double>(period);
  }

  // The filter filtered the frame at this display time (its history now ends there).
  void filtered(int64_t displayTimeNs, uint64_t poseSpace) {
    lastSpace_ = poseSpace;
    if (lastFilteredNs_ && displayTimeNs > *lastFilteredNs_) {
      steps_[stepCount_ % kPeriodSteps] = displayTimeNs - *lastFilteredNs_;
      ++stepCount_;
    }
    lastFilteredNs_ = displayTimeNs;
    worldLeft_ = false;
  }

  // The app's period as the recent steps give it; 0 before the first step.
  int64_t recentPeriod() const {
    const size_t n = std::min(stepCount_, kPeriodSteps);
    if (n == 0) return 0;
    return *std::min_element(steps_.begin(), steps_.begin() + static_cast<std::ptrdiff_t>(n));
  }

 private:
  bool worldLeft_ = false;
  std::optional<int64_t> lastFilteredNs_;
  uint64_t lastSpace_ = 0;
  std::array<int64_t, kPeriodSteps> steps_{};
  size_t stepCount_ = 0;
};

}  // namespace steadyxr::layer
