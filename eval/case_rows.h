// One case's rows of results.csv: every method's running sums summarised, with the facts of the
// case they share (motion changes, head speed, the ground truth's own stereo difference).
#pragma once

#include "frame_clock.h"
#include "frame_score.h"
#include "results.h"
#include "scenario.h"
#include "variants.h"

#include "steadyxr/imu/motion.h"

#include <vector>

namespace steadyxr::eval {

struct Scene;

struct CaseFacts {
  double gtStereo = 0;                // the ground truth's mean stereo difference over the case
  std::vector<int> motionChanges;     // frames at which the head motion (or a scene's content) changes
  double headSpeedP95 = 0;            // deg/s
  bool viewMovesWithoutHead = false;  // --locomotion: the app's rig moves the picture (not a still head)
  bool staticScene = true;            // no moving object
  bool cpuDevice = false;             // the device is a CPU (lavapipe): cost is wall time
  double truth8TemporalError = 0;     // temporal error of the 8-bit-rounded truth (metrics.h roundTo8Bit)
};

// The frames of a case at which its head motion changes: a preset's own change times (the first
// frame at or after each), else, for a trace, detected from the head speed.
std::vector<int> motionChangeFrames(const Scenario& sc, const imu::MotionStream& stream,
                                    const std::vector<double>& headSpeeds, const FrameClock& clock);

// Adds to `changes` (kept sorted, no repeats) the frame at or after each of `runTimes` (seconds since
// the clock's first frame).
void addChangeFrames(const std::vector<double>& runTimes, const FrameClock& clock, std::vector<int>* changes);
// Adds to `changes` (kept sorted, no repeats) the frames at or after each in-place content change of
// the scene (Scene::contentChanges: a cut, a fade's ends, a light switching): recovery counts from
// those too.
void addContentChangeFrames(const Scene& scene, const FrameClock& clock, std::vector<int>* changes);

// The row of method `v` in case `sc`; `none` is the unfiltered method's sums (ghosting is measured
// against it), nullptr when the run has no "none".
ResultRow resultRow(const Scenario& sc, const Variant& v, const Accum& a, const Accum* none,
                    const CaseFacts& facts);

}  // namespace steadyxr::eval
