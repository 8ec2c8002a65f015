// Orientation fusion (gyro integration + accelerometer tilt correction), the thread-safe pose
// history the render thread samples, and the device-to-host clock mapping.
#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "steadyxr/imu/hid_report.h"
#include "steadyxr/imu/pose_source.h"

namespace steadyxr::imu {

struct FusionParams {
  double tiltGainPerSec = 0.5;  // complementary filter: how fast tilt follows the accelerometer
  // Right after start the gain is 1/t (the tilt is the running mean of all accelerometer
  // samples: the head's linear acceleration averages out), capped here, down to tiltGainPerSec.
  double warmupGainPerSec = 20.0;
  double accelTimeConstantSec = 0.25;  // world-frame low-pass of the accelerometer before use
  double gateGyroRadPerSec = 0.2;   // no tilt correction while turning (>11 deg/s: centripetal acceleration)
  double gateAccelErrorMps2 = 0.6;  // ... nor while |accel| is far from g
  double biasGainPerSec = 0.05;     // integral gain of the gyro-bias estimate (tilt axes only)
  double maxBiasRadPerSec = 0.05;
  double speedTimeConstantSec = 0.03;  // one-pole smoothing of the head speed
  double maxStepSec = 0.05;            // longer gaps (dropped reports) are not integrated blindly
};

struct FusedSample {
  int64_t timeNs = 0;  // device clock
  glm::dquat orientation{1.0, 0.0, 0.0, 0.0};
  glm::dvec3 angularVelocityRadPerSec{0.0};
  double headSpeedDegPerSec = 0.0;
};

// Complementary filter on the unit quaternion. Yaw is unobservable without a magnetometer: it
// starts at 0 (the device's power-on heading) and is pure gyro integration.
class Fusion {
 public:
  explicit Fusion(const FusionParams& p = {}) : p_(p) {}
  // Returns false (and changes nothing) for samples not newer than the last one.
  bool update(const hid::ImuSample& s);
  const FusedSample& state() const { return state_; }
  bool initialized() const { return initialized_; }
  uint64_t rejectedSamples() const { return rejected_; }
  glm::dvec3 gyroBias() const { return gyroBias_; }

 private:
  FusionParams p_;
  FusedSample state_;
  bool initialized_ = false;
  int64_t startNs_ = 0;
  uint64_t rejected_ = 0;
  glm::dvec3 worldAccelLp_{0.0};
  glm::dvec3 gyroBias_{0.0};
  bool haveLp_ = false;
};

// Ring buffer of fused samples in the host time domain. One writer, any number of readers; a
// mutex held only for copies (a few hundred ns), so the render thread never waits long.
class PoseHistory final : public PoseSource {
 public:
  struct Params {
    size_t capacity = 4096;              // ~4 s at 1000 Hz
    int64_t maxPredictNs = 100'000'000;  // answer at most 100 ms beyond the newest sample
    int64_t maxBeforeOldestNs = 0;       // earlier than the oldest sample: no answer
  };
  PoseHistory() : PoseHistory(Params{}) {}
  explicit PoseHistory(const Params& p);

  // Samples must come in increasing time; older or equal ones are dropped and counted.
  void push(std::span<const FusedSample> samples);
  std::optional<HeadState> stateAt(int64_t timeNs) const override;
  size_t size() const;
  std::optional<int64_t> newestTimeNs() const;
  uint64_t outOfOrder() const;

 private:
  Params p_;
  mutable std::mutex mu_;
  std::vector<FusedSample> ring_;
  size_t head_ = 0;  // index of the oldest
  size_t count_ = 0;
  uint64_t outOfOrder_ = 0;
};

// Maps device time to host CLOCK_MONOTONIC: offset = min(host receive - device time), the
// sample with the least transport latency, allowed to creep up slowly (clock drift) and reset
// when it is far off (device restarted, host suspended).
class ClockMapper {
 public:
  int64_t update(int64_t hostReceiveNs, int64_t deviceNs);  // returns the current offset
  int64_t toHost(int64_t deviceNs) const { return deviceNs + offset_; }
  bool valid() const { return valid_; }
  uint64_t resets() const { return resets_; }

 private:
  bool valid_ = false;
  int64_t offset_ = 0;
  int64_t lastHostNs_ = 0;
  uint64_t resets_ = 0;
};

}  // namespace steadyxr::imu
