// Summarising a case's running sums into its rows of results.csv.
#include "case_rows.h"

#include "metrics.h"
#include "scene.h"

#include "steadyxr/core/params.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace steadyxr::eval {

std::vector<int> motionChangeFrames(const Scenario& sc, const imu::MotionStream& stream,
                                    const std::vector<double>& headSpeeds, const FrameClock& clock) {
  std::vector<int> changes;
  if (sc.trace) {
    changes = detectMotionChanges(headSpeeds, kMotionChangeDegPerSec);
  } else {
    for (double tc : stream.motionChangeTimes()) {
      const int k = clock.firstFrameAtOrAfter(tc);
      if (k >= 0 && (changes.empty() || changes.back() != k)) changes.push_back(k);
    }
  }
  return changes;
}

namespace {

// Adds the frame each change time is first seen on (frameAt: -1 when none), keeping the list sorted
// and without repeats.
template <class FrameAt>
void mergeChangeFrames(const std::vector<double>& times, FrameAt frameAt, std::vector<int>* changes) {
  for (double tc : times) {
    const int k = frameAt(tc);
    if (k >= 0) changes->push_back(k);
  }
  std::sort(changes->begin(), changes->end());
  changes->erase(std::unique(changes->begin(), changes->end()), changes->end());
}

}  // namespace

void addChangeFrames(const std::vector<double>& runTimes, const FrameClock& clock,
                     std::vector<int>* changes) {
  mergeChangeFrames(
      runTimes, [&](double t) { return clock.firstFrameAtOrAfterRunTime(t); }, changes);
}

void addContentChangeFrames(const Scene& scene, const FrameClock& clock, std::vector<int>* changes) {
  if (!scene.contentChanges) return;
  mergeChangeFrames(
      scene.contentChanges(clock.firstSec(), clock.lastSec()),
      [&](double t) { return clock.firstFrameAtOrAfter(t); }, changes);
}

ResultRow resultRow(const Scenario& sc, const Variant& v, const Accum& a, const Accum* none,
                    const CaseFacts& facts) {
  ResultRow r;
  r.scenario = sc.label;
  r.scene = sc.scene;
  r.motion = sc.trace ? std::filesystem::path(sc.motion).stem().string() : sc.motion;
  r.picture = isPictureScene(sc.scene) ? textureKey(sc.picture) : "";
  r.motionClass = sc.motionClass;
  r.pictureClass = sc.pictureClass;
  r.method = v.name;
  r.filterMethod = v.oracle ? "oracle" : core::methodName(v.params);
  r.sweep = v.sweep;
  r.stereo = v.params.stereo;
  r.jitter = v.jitter;
  r.depthGiven = sc.depthGiven;
  r.source = v.source;
  r.mtcd = safeDiv(a.mtcdSum, a.mtcdN);
  r.temporalError = safeDiv(a.tempErrSum, a.tempErrN);
  r.temporalErrorTruth8 = facts.truth8TemporalError;
  r.mtcdDisplay = safeDiv(a.mtcdDispSum, a.mtcdDispN);
  r.rmse = std::sqrt(safeDiv(a.sqErr, a.sqN));
  r.ssim = safeDiv(a.ssimSum, a.ssimN);
  r.rmseDisplay = std::sqrt(safeDiv(a.sqErrDisp, a.sqDispN));
  r.errPxDisplayPct = 100.0 * safeDiv(a.errPxDisp, a.errPxDispN);
  r.stereoError = safeDiv(a.stereoErrSum, a.stereoErrN);
  r.stereoDiff = safeDiv(a.stereoSum, a.stereoN);
  r.stereoDiffGt = facts.gtStereo;
  r.stereoGap = std::fabs(r.stereoDiff - facts.gtStereo);
  if (none != nullptr) {
    const Ghosting g = ghostingPerFrame(a.frameRmse, none->frameRmse, facts.motionChanges);
    r.ghostWorstRatio = g.worstRatio;
    r.ghostWorstFrame = g.worstFrame;
    r.recoveryFrames = g.recoveryFrames;
    r.recovered = g.recovered;
  }
  r.motionChanges = int(facts.motionChanges.size());
  r.headSpeedP95 = facts.headSpeedP95;
  r.lowSpeed = facts.headSpeedP95 < kLowSpeedDegPerSec && !facts.viewMovesWithoutHead;
  r.staticScene = facts.staticScene;
  // lavapipe's timestamps miss dispatches that no barrier waits for (measured: hybrid 0.1 ms
  // by timestamps, 3.5 ms from submit to idle, at 256x256), and its "GPU" is this CPU anyway:
  // there the cost is the wall time from submit to idle. Real GPUs: timestamps.
  r.gpuMs = facts.cpuDevice ? a.timedWallMs : a.timedGpuMs;
  r.gpuTemporalMs = safeDiv(a.gpuTemporal, a.gpuN);
  r.gpuStereoMs = safeDiv(a.gpuStereo, a.gpuN);
  r.gpuOtherMs = safeDiv(a.gpuOther, a.gpuN);
  r.renderMs = safeDiv(a.renderMs, a.renderN);
  r.cpuUs = safeDiv(a.cpuUs, a.cpuN);
  return r;
}

}  // namespace steadyxr::eval
