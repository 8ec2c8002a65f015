// The steadyxr head-IMU HID report format (documented in imu/README.md), its report descriptor,
// an encoder (the emulator) and a robust stateful parser (the reader). Byte order: little endian.
//
// Input report, ID 1, 57 bytes:
//   [0]      report ID (1)
//   [1..2]   u16 sample counter of the first sample (counts samples, wraps)
//   [3..4]   u16 sample interval, microseconds (1000 = 1000 Hz)
//   [5..8]   u32 device timestamp of the first sample, microseconds (wraps after ~71.6 min)
//   [9..56]  4 samples x { i16 gyro x,y,z (1e-3 rad/s); i16 accel x,y,z (1e-3 m/s^2) }
// Axes: head frame, OpenXR convention (+X right, +Y up, -Z forward). The accelerometer reports
// specific force (reads +9.81 on +Y at rest, upright). +-32767 means saturated; -32768 is invalid.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

namespace steadyxr::imu::hid {

inline constexpr uint8_t kReportId = 0x01;
inline constexpr size_t kSamplesPerReport = 4;
inline constexpr size_t kHeaderBytes = 9;
inline constexpr size_t kSampleBytes = 12;
inline constexpr size_t kReportBytes = kHeaderBytes + kSamplesPerReport * kSampleBytes;  // 57
inline constexpr double kGyroLsb = 1e-3;   // rad/s per count  (HID unit exponent -3)
inline constexpr double kAccelLsb = 1e-3;  // m/s^2 per count (HID unit exponent -3)
inline constexpr int16_t kRawMax = 32767;
inline constexpr uint16_t kDefaultIntervalUs = 1000;
// pid.codes test VID/PID: fine for an emulator and for development, not for a shipped product.
inline constexpr uint16_t kVendorId = 0x1209;
inline constexpr uint16_t kProductId = 0x0001;

using Report = std::array<uint8_t, kReportBytes>;

struct RawReport {
  uint16_t counter = 0;
  uint16_t intervalUs = kDefaultIntervalUs;
  uint32_t timestampUs = 0;
  std::array<std::array<int16_t, 6>, kSamplesPerReport> samples{};  // gx gy gz ax ay az
};

// The HID report descriptor the device (or emulator) serves.
std::vector<uint8_t> reportDescriptor();

Report encode(const RawReport& r);
// Rounds value/lsb to the nearest count and clamps to +-32767; sets *saturated when clamped.
int16_t quantize(double value, double lsb, bool* saturated = nullptr);

enum class DecodeStatus { kOk, kTooShort, kTooLong, kWrongReportId };
// kTooLong still fills *out from the first kReportBytes (trailing bytes ignored).
DecodeStatus decode(std::span<const uint8_t> bytes, RawReport* out);

// Byte-stream framing for the non-HID transports (FIFO, file): 0xA5 0x5A, u8 length, report.
inline constexpr uint8_t kFrameMagic0 = 0xA5;
inline constexpr uint8_t kFrameMagic1 = 0x5A;
std::vector<uint8_t> frame(std::span<const uint8_t> report);

// Splits a byte stream back into reports, resynchronising on the magic after garbage.
class FrameDecoder {
 public:
  void feed(std::span<const uint8_t> bytes);
  bool next(std::vector<uint8_t>* report);  // false: need more bytes
  uint64_t garbageBytes() const { return garbage_; }

 private:
  std::vector<uint8_t> buf_;
  size_t pos_ = 0;
  uint64_t garbage_ = 0;
};

// One IMU sample after parsing: device time (ns, unwrapped, continuous), SI units, head frame.
struct ImuSample {
  int64_t deviceTimeNs = 0;
  glm::vec3 gyroRadPerSec{0.0f};
  glm::vec3 accelMps2{0.0f};
  bool accelValid = true;  // false when saturated or repaired: fusion skips its tilt correction
};

struct ParserStats {
  uint64_t reports = 0;             // accepted
  uint64_t samples = 0;             // emitted
  uint64_t tooShort = 0;            // skipped
  uint64_t tooLong = 0;             // accepted, trailing bytes ignored
  uint64_t wrongReportId = 0;       // skipped
  uint64_t duplicates = 0;          // same counter again: skipped
  uint64_t droppedReports = 0;      // counter gaps, in reports
  uint64_t counterAnomalies = 0;    // counter backwards / huge jump (device reset or corruption)
  uint64_t suspectReports = 0;      // neither counter nor timestamp sane: skipped
  uint64_t timestampWraps = 0;      // u32 microsecond wrap-around, handled
  uint64_t timestampBackwards = 0;  // non-monotonic: repaired from the counter
  uint64_t timestampJumps = 0;      // disagrees with the counter: repaired from the counter
  uint64_t badIntervals = 0;        // interval field 0 or absurd: previous one used
  uint64_t saturatedValues = 0;     // counts at +-32767 (kept) or -32768 (clamped)
  uint64_t implausibleSamples = 0;  // gyro step no head can make: previous sample held
  uint64_t garbageBytes = 0;        // stream transports: bytes skipped while resynchronising
};

class ReportParser {
 public:
  // Appends the report's samples to *out; returns how many. Never throws, never emits NaN.
  size_t parse(std::span<const uint8_t> bytes, std::vector<ImuSample>* out);
  const ParserStats& stats() const { return stats_; }
  ParserStats& mutableStats() { return stats_; }

 private:
  ParserStats stats_;
  bool have_ = false;
  uint16_t lastCounter_ = 0;
  uint32_t lastTimestampUs_ = 0;
  uint16_t intervalUs_ = kDefaultIntervalUs;
  int64_t lastDeviceNs_ = 0;  // device time of the last report's first sample
  glm::vec3 lastGyro_{0.0f};
  bool pending_ = false;  // a suspect report that a following one may confirm (device restart)
  uint16_t pendingCounter_ = 0;
  uint32_t pendingTimestampUs_ = 0;
};

}  // namespace steadyxr::imu::hid
