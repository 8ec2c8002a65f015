// One result row per (case, method) of an evaluation run, and the files and table they go to.
#pragma once

#include <string>
#include <vector>

namespace steadyxr::eval {

struct Options;

struct ResultRow {
  std::string scenario, scene, motion, picture, method, filterMethod;
  std::string motionClass, pictureClass;  // corpus grouping (motion preset family, picture family)
  bool sweep = false, stereo = false, jitter = false, depthGiven = true;
  int source = 1;
  double mtcd = 0, mtcdDisplay = 0, rmse = 0, ssim = 0, rmseDisplay = 0, errPxDisplayPct = 0;
  double temporalError = 0;                                // vs ground truth, 8-bit units (metrics.h)
  double temporalErrorTruth8 = 0;                          // of the truth rounded to 8 bits (the floor)
  double stereoError = 0;                                  // per pixel, 8-bit units (metrics.h)
  double stereoDiff = 0, stereoDiffGt = 0, stereoGap = 0;  // the former image-wide measure, kept in the CSV
  double ghostWorstRatio = 0;                              // worst frame's RMSE / none's in that frame
  int ghostWorstFrame = -1, recoveryFrames = 0;            // frames after a motion change until <= none
  bool recovered = true;
  int motionChanges = 0;    // changes detected in the case (same for every method)
  double headSpeedP95 = 0;  // 95th percentile of the head speed over the case, deg/s
  bool lowSpeed = false;    // headSpeedP95 < kLowSpeedDegPerSec: a shimmer case
  bool staticScene = true;  // no moving object (the oracle is defined there)
  double gpuMs = 0, gpuTemporalMs = 0, gpuStereoMs = 0, gpuOtherMs = 0, renderMs = 0, costMs = 0, cpuUs = 0;
};

struct TargetCheck {
  std::string name, detail;
  bool met = false;
  bool evaluated = false;
};

// A case counts as low head speed (a shimmer case) when the 95th percentile of its per-frame head
// speed is below this: under fixation tremor the head stays below a few deg/s (README, seed 003's
// h_max is 25 deg/s), pursuit runs at 20 deg/s.
inline constexpr double kLowSpeedDegPerSec = 5.0;
// A motion change (stop, start, saccade) is a frame-to-frame change in head speed of at least
// this: above the speed changes of fixation tremor (a few deg/s), below a 0.2 deg saccade within
// one 30 Hz frame (6 deg/s) and a pursuit's start or stop (20 deg/s).
inline constexpr double kMotionChangeDegPerSec = 5.0;

const ResultRow* findRow(const std::vector<ResultRow>& rows, const std::string& scenario,
                         const std::string& method);

void writeResultsCsv(const std::string& path, const std::vector<ResultRow>& rows);
void writeResultsJson(const std::string& path, const Options& o, const std::vector<ResultRow>& rows,
                      const std::vector<TargetCheck>& targets, const std::string& device, double seconds);
// The per-case table (every row, when perCase), then the targets as MET / MISSED lines.
void printResults(const std::vector<ResultRow>& rows, const std::vector<TargetCheck>& targets, bool perCase);

std::string fmt(double v, int prec = 5);
std::string csvEscape(const std::string& s);

}  // namespace steadyxr::eval
