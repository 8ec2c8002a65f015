#include "steadyxr/imu/hid_report.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace steadyxr::imu::hid {
namespace {

// Short-item prefixes (HID 1.11 §6.2.2.2): tag | type | size code.
enum : uint8_t {
  kInput = 0x80,
  kCollection = 0xA0,
  kEndCollection = 0xC0,
  kUsagePage = 0x04,
  kLogicalMin = 0x14,
  kLogicalMax = 0x24,
  kUnitExponent = 0x54,
  kUnit = 0x64,
  kReportSize = 0x74,
  kReportIdItem = 0x84,
  kReportCount = 0x94,
  kUsage = 0x08,
};

class DescriptorWriter {
 public:
  // size: 0, 1, 2 or 4 data bytes (little endian).
  DescriptorWriter& item(uint8_t prefix, uint32_t value, int size) {
    const uint8_t code = size == 4 ? 3 : static_cast<uint8_t>(size);
    bytes_.push_back(static_cast<uint8_t>(prefix | code));
    for (int i = 0; i < size; ++i) bytes_.push_back(static_cast<uint8_t>(value >> (8 * i)));
    return *this;
  }
  std::vector<uint8_t> take() { return std::move(bytes_); }

 private:
  std::vector<uint8_t> bytes_;
};

constexpr uint16_t kSensorPage = 0x0020;
constexpr uint16_t kVendorPage = 0xFF00;
constexpr uint8_t kVar = 0x02, kWrap = 0x08;  // Input flags (Data, Abs implied by 0 bits)

void put16(uint8_t* p, uint16_t v) {
  p[0] = static_cast<uint8_t>(v);
  p[1] = static_cast<uint8_t>(v >> 8);
}
void put32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
uint16_t get16(const uint8_t* p) {
  return static_cast<uint16_t>(p[0] | (p[1] << 8));
}
uint32_t get32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | (static_cast<uint32_t>(p[1]) << 8) |
         (static_cast<uint32_t>(p[2]) << 16) | (static_cast<uint32_t>(p[3]) << 24);
}

// No head turns faster than this between two 1 ms samples; beyond it the bytes are corrupt.
constexpr float kMaxGyroStepRadPerSec = 6.0f;
constexpr int64_t kMaxReportGapUs = 1'000'000;

}  // namespace

std::vector<uint8_t> reportDescriptor() {
  DescriptorWriter d;
  // Vendor-defined top level on purpose: with Sensor-page physical collections the kernel's
  // hid-sensor-hub would claim the device and no hidraw node would appear.
  d.item(kUsagePage, kVendorPage, 2).item(kUsage, 0x01, 1).item(kCollection, 0x01, 1);  // Application
  d.item(kReportIdItem, kReportId, 1);
  // Sample counter (vendor usage 2): counts samples, wraps.
  d.item(kUsage, 0x02, 1).item(kLogicalMin, 0, 1).item(kLogicalMax, 0xFFFF, 4);
  d.item(kReportSize, 16, 1).item(kReportCount, 1, 1).item(kInput, kVar | kWrap, 1);
  // Sensor page: Property: Report Interval (0x030E), microseconds.
  d.item(kUsagePage, kSensorPage, 1).item(kUsage, 0x030E, 2);
  d.item(kUnit, 0x1001, 2).item(kUnitExponent, 0x0A, 1);  // SI linear, seconds; 10^-6
  d.item(kInput, kVar, 1);
  // Data Field: Timestamp (0x0529), microseconds, 32 bit, wraps.
  d.item(kUsage, 0x0529, 2).item(kLogicalMax, 0xFFFFFFFFu, 4).item(kReportSize, 32, 1);
  d.item(kInput, kVar | kWrap, 1);
  for (size_t i = 0; i < kSamplesPerReport; ++i) {
    // Motion: Gyrometer 3D (0x76): Data Field: Angular Velocity X/Y/Z (0x0457..0x0459), rad/s e-3.
    d.item(kUsage, 0x76, 1).item(kCollection, 0x02, 1);  // Logical
    d.item(kUsage, 0x0457, 2).item(kUsage, 0x0458, 2).item(kUsage, 0x0459, 2);
    d.item(kLogicalMin, 0x8001, 2).item(kLogicalMax, 0x7FFF, 2);  // -32767..32767
    d.item(kUnit, 0xF012, 2).item(kUnitExponent, 0x0D, 1);        // SI rotation: rad s^-1; 10^-3
    d.item(kReportSize, 16, 1).item(kReportCount, 3, 1).item(kInput, kVar, 1);
    d.item(kEndCollection, 0, 0);
    // Motion: Accelerometer 3D (0x73): Data Field: Acceleration X/Y/Z (0x0453..0x0455), m/s^2 e-3.
    d.item(kUsage, 0x73, 1).item(kCollection, 0x02, 1);
    d.item(kUsage, 0x0453, 2).item(kUsage, 0x0454, 2).item(kUsage, 0x0455, 2);
    d.item(kUnit, 0xE011, 2).item(kUnitExponent, 0x0D, 1);  // SI linear: m s^-2; 10^-3
    d.item(kInput, kVar, 1);
    d.item(kEndCollection, 0, 0);
  }
  d.item(kEndCollection, 0, 0);
  return d.take();
}

int16_t quantize(double value, double lsb, bool* saturated) {
  const double counts = value / lsb;
  const bool sat = !(std::abs(counts) < kRawMax);  // also catches NaN
  if (saturated) *saturated = sat;
  if (std::isnan(counts)) return 0;
  return static_cast<int16_t>(std::lround(std::clamp(counts, -double(kRawMax), double(kRawMax))));
}

Report encode(const RawReport& r) {
  Report out{};
  out[0] = kReportId;
  put16(&out[1], r.counter);
  put16(&out[3], r.intervalUs);
  put32(&out[5], r.timestampUs);
  for (size_t s = 0; s < kSamplesPerReport; ++s)
    for (size_t k = 0; k < 6; ++k)
      put16(&out[kHeaderBytes + s * kSampleBytes + 2 * k], static_cast<uint16_t>(r.samples[s][k]));
  return out;
}

DecodeStatus decode(std::span<const uint8_t> bytes, RawReport* out) {
  if (bytes.empty() || bytes[0] != kReportId)
    return bytes.empty() ? DecodeStatus::kTooShort : DecodeStatus::kWrongReportId;
  if (bytes.size() < kReportBytes) return DecodeStatus::kTooShort;
  const uint8_t* p = bytes.data();
  out->counter = get16(p + 1);
  out->intervalUs = get16(p + 3);
  out->timestampUs = get32(p + 5);
  for (size_t s = 0; s < kSamplesPerReport; ++s)
    for (size_t k = 0; k < 6; ++k)
      out->samples[s][k] = static_cast<int16_t>(get16(p + kHeaderBytes + s * kSampleBytes + 2 * k));
  return bytes.size() > kReportBytes ? DecodeStatus::kTooLong : DecodeStatus::kOk;
}

std::vector<uint8_t> frame(std::span<const uint8_t> report) {
  const size_t n = std::min<size_t>(report.size(), 255);
  // Sized up front and filled by copy: growing a 3-byte vector by insert() trips GCC 12's
  // -Warray-bounds false positive at -O3.
  std::vector<uint8_t> out(3 + n);
  out[0] = kFrameMagic0;
  out[1] = kFrameMagic1;
  out[2] = static_cast<uint8_t>(n);
  std::copy_n(report.begin(), n, out.begin() + 3);
  return out;
}

void FrameDecoder::feed(std::span<const uint8_t> bytes) {
  if (pos_ > 4096) {  // compact now and then, not on every call
    buf_.erase(buf_.begin(), buf_.begin() + static_cast<std::ptrdiff_t>(pos_));
    pos_ = 0;
  }
  buf_.insert(buf_.end(), bytes.begin(), bytes.end());
}

bool FrameDecoder::next(std::vector<uint8_t>* report) {
  while (buf_.size() - pos_ >= 3) {
    const uint8_t len = buf_[pos_ + 2];
    if (buf_[pos_] != kFrameMagic0 || buf_[pos_ + 1] != kFrameMagic1 || len == 0) {
      ++pos_;
      ++garbage_;
      continue;
    }
    if (buf_.size() - pos_ < 3u + len) return false;
    report->assign(buf_.begin() + static_cast<std::ptrdiff_t>(pos_ + 3),
                   buf_.begin() + static_cast<std::ptrdiff_t>(pos_ + 3 + len));
    pos_ += 3u + len;
    return true;
  }
  return false;
}

size_t ReportParser::parse(std::span<const uint8_t> bytes, std::vector<ImuSample>* out) {
  RawReport r;
  switch (decode(bytes, &r)) {
    case DecodeStatus::kTooShort:
      ++stats_.tooShort;
      return 0;
    case DecodeStatus::kWrongReportId:
      ++stats_.wrongReportId;
      return 0;
    case DecodeStatus::kTooLong:
      ++stats_.tooLong;
      break;
    case DecodeStatus::kOk:
      break;
  }
  if (r.intervalUs == 0 || r.intervalUs > 50'000) {
    ++stats_.badIntervals;
    r.intervalUs = intervalUs_;
  }
  const int64_t n = static_cast<int64_t>(kSamplesPerReport);
  bool contiguous = false;
  int64_t deviceNs = 0;
  const bool first = !have_;
  const int64_t previousNs = lastDeviceNs_;
  if (!have_) {
    deviceNs = static_cast<int64_t>(r.timestampUs) * 1000;
  } else {
    const uint16_t dc = static_cast<uint16_t>(r.counter - lastCounter_);
    if (dc == 0) {
      ++stats_.duplicates;
      return 0;
    }
    // Both clocks of the device, the sample counter and the timestamp, must agree; whichever is
    // sane wins, so the output time stays continuous whatever the device sends.
    const int64_t byCounterUs = static_cast<int64_t>(dc) * intervalUs_;
    const bool counterOk = dc < 0x8000 && byCounterUs <= kMaxReportGapUs;
    const int64_t dts = static_cast<int32_t>(r.timestampUs - lastTimestampUs_);
    const bool tsOk = dts > 0 && dts <= kMaxReportGapUs;
    if (tsOk && r.timestampUs < lastTimestampUs_) ++stats_.timestampWraps;
    int64_t stepUs = n * intervalUs_;
    if (counterOk && tsOk) {
      const int64_t tolerance = std::max<int64_t>(10'000, byCounterUs / 4);
      if (std::abs(dts - byCounterUs) <= tolerance) {
        stepUs = dts;
      } else {
        ++stats_.timestampJumps;
        stepUs = byCounterUs;
      }
    } else if (counterOk) {
      if (dts <= 0)
        ++stats_.timestampBackwards;
      else
        ++stats_.timestampJumps;
      stepUs = byCounterUs;
    } else if (tsOk) {
      ++stats_.counterAnomalies;
      stepUs = dts;
    } else {
      // Neither clock is sane: corruption, or a device that restarted. Hold the report back and
      // accept a restart only when the next report agrees with it.
      const uint16_t pc = static_cast<uint16_t>(r.counter - pendingCounter_);
      const int64_t pts = static_cast<int32_t>(r.timestampUs - pendingTimestampUs_);
      const bool confirmsPending = pending_ && pc > 0 && pc < 0x8000 && pts > 0 && pts <= kMaxReportGapUs &&
                                   std::abs(pts - int64_t(pc) * intervalUs_) <= 10'000;
      if (!confirmsPending) {
        pending_ = true;
        pendingCounter_ = r.counter;
        pendingTimestampUs_ = r.timestampUs;
        ++stats_.suspectReports;
        return 0;
      }
      ++stats_.counterAnomalies;
    }
    pending_ = false;
    if (counterOk && dc > n && dc % n == 0) stats_.droppedReports += dc / n - 1;
    contiguous = counterOk && dc == n;
    deviceNs = lastDeviceNs_ + stepUs * 1000;
  }
  have_ = true;
  lastCounter_ = r.counter;
  lastTimestampUs_ = r.timestampUs;
  intervalUs_ = r.intervalUs;
  lastDeviceNs_ = deviceNs;
  ++stats_.reports;

  const float gapAllowance =
      first ? 1e9f
            : static_cast<float>(std::min<int64_t>(deviceNs - previousNs, kMaxReportGapUs * 1000)) * 1e-6f;
  for (size_t s = 0; s < kSamplesPerReport; ++s) {
    ImuSample out1;
    out1.deviceTimeNs = deviceNs + static_cast<int64_t>(s) * r.intervalUs * 1000;
    float v[6];
    bool accelSat = false;
    for (size_t k = 0; k < 6; ++k) {
      int16_t raw = r.samples[s][k];
      if (raw == INT16_MIN) raw = -kRawMax;  // outside the logical range
      if (raw == kRawMax || raw == -kRawMax) {
        ++stats_.saturatedValues;
        if (k >= 3) accelSat = true;
      }
      v[k] = static_cast<float>(raw * (k < 3 ? kGyroLsb : kAccelLsb));
    }
    out1.gyroRadPerSec = {v[0], v[1], v[2]};
    out1.accelMps2 = {v[3], v[4], v[5]};
    out1.accelValid = !accelSat;
    {
      // After a gap the head may have sped up more; allow ~1000 rad/s^2 over the gap.
      const float allowed = kMaxGyroStepRadPerSec + (s == 0 && !contiguous ? gapAllowance : 0.0f);
      const glm::vec3 d = out1.gyroRadPerSec - lastGyro_;
      if (std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)}) > allowed) {
        ++stats_.implausibleSamples;
        out1.gyroRadPerSec = lastGyro_;
        out1.accelValid = false;
      }
    }
    lastGyro_ = out1.gyroRadPerSec;
    out->push_back(out1);
    ++stats_.samples;
  }
  return kSamplesPerReport;
}

}  // namespace steadyxr::imu::hid
