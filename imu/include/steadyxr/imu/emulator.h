// The IMU emulator as a library: turns a MotionStream into byte-exact HID input reports
// (hid_report.h) and writes them to a transport. The steadyxr-imu-emu program is a CLI on top.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include <glm/vec3.hpp>

#include "steadyxr/imu/hid_report.h"
#include "steadyxr/imu/motion.h"

namespace steadyxr::imu {

struct EmulatorParams {
  double sampleRateHz = 1000.0;
  uint32_t timestampStartUs = 0;  // set near 2^32 to exercise the wrap-around
  uint16_t counterStart = 0;
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

 private:
  const MotionStream& stream_;
  EmulatorParams p_;
  uint16_t intervalUs_;
  uint64_t sampleIndex_ = 0;
  uint64_t saturated_ = 0;
  struct Noise;
  std::unique_ptr<Noise> noise_;
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
