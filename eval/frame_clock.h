// When each submitted frame is shown: the app's frame times, with the frames it misses.
// An app that misses a frame's deadline submits its next frame for the display time after it
// (xrWaitFrame returns the next free one), so the layer sees one pose step of two app periods, or
// three after two misses in a row. `--drop-frames P` runs every case that way: the truth, the
// inputs and the poses the filters are told all follow the submitted frames' times.
#pragma once

#include <cstdint>
#include <vector>

namespace steadyxr::eval {

// At most this many periods missed in a row (a stall of four app periods; beyond that an app
// shows a loading screen, and the runtime has long since taken over the display).
constexpr int kMostMissedInARow = 3;

class FrameClock {
 public:
  // `frames` submitted frames, the first at firstSec, one app period (dt) apart where none is
  // missed; each period after a submitted frame is missed with probability dropFraction (drawn from
  // `seed`, the same for every case of a run), at most kMostMissedInARow in a row. dropFraction <= 0:
  // every period shown, frame f at firstSec + f * dt exactly.
  FrameClock(int frames, double firstSec, double dt, double dropFraction, uint64_t seed);

  int frames() const { return static_cast<int>(periods_.size()); }
  double firstSec() const { return firstSec_; }
  double dt() const { return dt_; }
  // Frame f's display time on the run's clock, and its app period since the first frame.
  double timeOf(int f) const { return firstSec_ + periods_[f] * dt_; }
  int64_t periodOf(int f) const { return periods_[f]; }
  double lastSec() const { return timeOf(frames() - 1); }
  // App periods missed over the run.
  int64_t missedPeriods() const { return periods_.empty() ? 0 : periods_.back() - (frames() - 1); }
  // The first frame shown at or after time t (a change at t is first seen there); -1 when t is
  // after the last frame or a period or more before the first.
  int firstFrameAtOrAfter(double t) const { return firstFrameAtOrAfterRunTime(t - firstSec_); }
  // The same for a time counted from the first frame.
  int firstFrameAtOrAfterRunTime(double sinceFirstSec) const;

 private:
  double firstSec_;
  double dt_;
  std::vector<int64_t> periods_;  // frame f's app period since the first frame
};

// The span of a run's frames in app periods, as the FrameClock with these arguments has it
// (the corpus places its window before the clock exists).
int64_t spanInPeriods(int frames, double dropFraction, uint64_t seed);
// App periods that run misses (for its report, without building the clock).
inline int64_t missedPeriods(int frames, double dropFraction, uint64_t seed) {
  return frames > 0 ? spanInPeriods(frames, dropFraction, seed) - (frames - 1) : 0;
}

}  // namespace steadyxr::eval
