// The IMU emulator as a library: turns a MotionStream into byte-exact HID input reports
// (hid_report.h) and writes them to a transport. The steadyxr-imu-emu program is a CLI on top.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include <glm/ext/vector_double3.hpp>
#include <glm/vec3.hpp>

#include "steadyxr/imu/hid_report.h"
#include "steadyxr/imu/motion.h"

namespace steadyxr::imu {

// Errors of a consumer MEMS IMU, per axis, at the figures of the Bosch BMI160 datasheet
// (BST-BMI160-DS000): white noise given as a density, so the per-sample standard deviation is
// density * sqrt(sample rate) (the continuous-time convention of Allan-variance IMU models).
struct SensorModel {
  bool enabled = true;
  double gyroNoiseDensityDegPerSecRtHz = 0.007;  // BMI160 gyro output noise, typical
  // Residual zero-rate offset at start-up, sigma: the datasheet's +-3 deg/s is before offset
  // compensation; 0.05 deg/s is what its temperature drift (0.05 deg/s/K) leaves after it.
  double gyroBiasSigmaDegPerSec = 0.05;
  // Bias random walk: wanders by ~3 deg/h (8e-4 deg/s) in 100 s, the bias instability of
  // consumer MEMS gyros (a few deg/h in Allan-deviation plots; the datasheet gives none).
  double gyroBiasRandomWalkDegPerSecRtSec = 8e-5;
  double accelNoiseDensityUgRtHz = 180.0;  // BMI160 accelerometer output noise, typical
  // Residual accelerometer offset, sigma: the datasheet's +-40 mg is before calibration;
  // 2 mg after (a 0.11 deg tilt error that no fusion without a reference can remove).
  double accelBiasSigmaMg = 2.0;
};

// The model's state for one device: draws the start-up biases, then per sample adds white noise
// and advances the gyro bias's random walk. Deterministic for a seed.
class SensorErrors {
 public:
  SensorErrors(const SensorModel& m, double sampleRateHz, uint64_t seed);
  ~SensorErrors();
  void apply(glm::dvec3* gyroRadPerSec, glm::dvec3* accelMps2);
  glm::dvec3 gyroBiasRadPerSec() const { return gyroBias_; }
  glm::dvec3 accelBiasMps2() const { return accelBias_; }
  double gyroNoiseSigmaRadPerSec() const { return gyroSigma_; }  // per sample
  double accelNoiseSigmaMps2() const { return accelSigma_; }     // per sample

 private:
  struct Rng;
  std::unique_ptr<Rng> rng_;
  glm::dvec3 gyroBias_{0.0}, accelBias_{0.0};
  double gyroSigma_ = 0.0, accelSigma_ = 0.0, biasStep_ = 0.0;
};

struct EmulatorParams {
  double sampleRateHz = 1000.0;
  uint32_t timestampStartUs = 0;  // set near 2^32 to exercise the wrap-around
  uint16_t counterStart = 0;
  SensorModel sensor;  // on by default; sensor.enabled = false gives the exact (quantised) values
  // Extra errors on top of the model (fault injection and tests):
  double gyroNoiseRadPerSec = 0.0;  // white noise, per sample, per axis (deterministic for a seed)
  double accelNoiseMps2 = 0.0;
  glm::vec3 gyroBiasRadPerSec{0.0f};
  uint64_t seed = 1;
};

// Samples the stream at t_k = k * interval (the device clock) and packs kSamplesPerReport
// samples per report. Gyro = head-frame angular velocity; accelerometer = specific force
// R^T (a - g), g = (0, -9.80665, 0) in the world (OpenXR +Y up).
class ReportGenerator {
 public:
  ReportGenerator(const MotionStream& stream, const EmulatorParams& p);
  ~ReportGenerator();
  hid::Report next();
  double timeOfNextSampleSec() const;  // simulated time of the next report's first sample
  uint16_t intervalUs() const { return intervalUs_; }
  uint64_t saturatedValues() const { return saturated_; }
  const SensorErrors* sensorErrors() const { return sensor_.get(); }  // nullptr when the model is off

 private:
  const MotionStream& stream_;
  EmulatorParams p_;
  uint16_t intervalUs_;
  uint64_t sampleIndex_ = 0;
  uint64_t saturated_ = 0;
  struct Noise;
  std::unique_ptr<Noise> noise_;
  std::unique_ptr<SensorErrors> sensor_;
};

class ReportSink {
 public:
  virtual ~ReportSink() = default;
  virtual bool write(std::span<const uint8_t> report) = 0;
  // Bytes written as they are, no framing (fault injection for the stream transports).
  virtual bool writeRaw(std::span<const uint8_t> bytes) { return write(bytes); }
  virtual std::string describe() const = 0;
};

// "file:/path" (framed stream), "fifo:/path" (framed; created if missing; open blocks until a
// reader opens it), "socket:/path" (SOCK_SEQPACKET server, listens now, waits for the reader at
// the first write), "uhid" or "uhid:NAME" (a virtual HID device through /dev/uhid; hidapi then
// finds it as hidraw, VID:PID 1209:0001). nullptr and *error on failure.
std::unique_ptr<ReportSink> openReportSink(const std::string& spec, std::string* error);

}  // namespace steadyxr::imu
