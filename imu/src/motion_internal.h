// Building blocks shared by the motion generators (motion.cpp) and the presets
// (motion_presets.cpp): pose curves, rotation-vector helpers, band-limited random processes and
// the involuntary head jitter (tremor, drift, translation tremor, small jumps).
#pragma once

#include <algorithm>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "rng.h"
#include "steadyxr/imu/motion.h"
#include "steadyxr/imu/motion_extra.h"

namespace steadyxr::imu::detail {

using dquat = glm::dquat;
using dvec3 = glm::dvec3;

inline constexpr double kDegToRad = std::numbers::pi / 180.0;

struct Pose {
  dquat q{1.0, 0.0, 0.0, 0.0};
  dvec3 p{0.0};
};

dquat fromRotationVector(const dvec3& v);
dvec3 toRotationVector(dquat q);

// Eyes move on a sphere about the neck pivot when the head rotates.
inline dvec3 neckTranslation(const dquat& q) {
  const dvec3 neck(0.0, kNeckToEyesY, kNeckToEyesZ);
  return q * neck - neck;
}

inline double smootherstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * x * (x * (6.0 * x - 15.0) + 10.0);
}

// Base for streams defined by a pose curve; the curve must accept any t (also slightly < 0).
// Angular velocity and linear acceleration are central differences of the curve, so the gyro
// and accelerometer the emulator synthesises are consistent with the ground truth.
class PoseStream : public MotionStream {
 public:
  virtual Pose poseAt(double t) const = 0;
  virtual double derivativeStep() const { return 1e-4; }  // traces use their row spacing
  MotionState at(double t) const override;
};

// Band-limited Gaussian noise: white noise on a uniform grid through Butterworth high- and
// low-pass sections (each `order` = 2 * sections poles), filtered circularly until the start-up
// transient has died out, so the sequence is periodic and at(t) is defined (and smooth: cubic
// Catmull-Rom between grid points) for any t. Scaled to unit RMS over the period.
class BandNoise {
 public:
  BandNoise() = default;
  // loHz <= 0: low-pass only.
  BandNoise(Rng& rng, double gridHz, double periodSec, double loHz, double hiHz, int sections);
  double at(double t) const;
  // RMS of the time derivative (per unit of the signal's RMS), over the period.
  double derivativeRms() const { return derivativeRms_; }

 private:
  double gridHz_ = 1.0;
  std::vector<double> v_;
  double derivativeRms_ = 0.0;
};

// Involuntary head motion during fixation, in degrees (rotation vector) and metres.
struct JitterParams {
  double periodSec = 10.0;  // the random processes repeat after this (>= the run)
  double tremorAmplitudeDeg = 0.02, tremorLowHz = 8.0, tremorHighHz = 12.0;
  double driftDegPerSec = 0.1;
  double translationTremorMm = 0.2;
};

class Jitter {
 public:
  Jitter() = default;
  Jitter(const JitterParams& p, uint64_t seed);
  dvec3 rotationDeg(double t) const;  // 0 at t = 0
  dvec3 translation(double t) const;  // 0 at t = 0

 private:
  dvec3 raw(const BandNoise (&n)[3], const double (&scale)[3], double t) const;
  BandNoise tremor_[3], drift_[3], sway_[3];
  double tremorScale_[3] = {0, 0, 0}, driftScale_[3] = {0, 0, 0}, swayScale_[3] = {0, 0, 0};
  dvec3 rotation0_{0.0}, translation0_{0.0};
};

// A quick rotation of the head by `deg` (rotation vector) starting at t over rampSec.
struct Jump {
  double t = 0.0, rampSec = 0.06;
  dvec3 deg{0.0};
  dvec3 at(double time) const { return deg * smootherstep((time - t) / rampSec); }
};

// Angle (rad) of a turn at speed radPerSec starting at 0, lasting durationSec, with raised-cosine
// speed ramps of rampIn/rampOut seconds at each end (speed and acceleration continuous).
double rampedTurnAngle(double t, double durationSec, double rampIn, double rampOut, double radPerSec);

std::string formatText(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

}  // namespace steadyxr::imu::detail
