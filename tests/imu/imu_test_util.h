// Shared helpers of the IMU tests: emulator -> real report bytes -> parser -> fusion.
#pragma once

#include <cmath>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "steadyxr/imu/emulator.h"
#include "steadyxr/imu/fusion.h"
#include "steadyxr/imu/hid_report.h"
#include "steadyxr/imu/motion.h"

namespace steadyxr::imu::test {

inline double angleDeg(glm::dquat a, glm::dquat b) {
  const glm::dquat d = glm::conjugate(a) * b;
  const double v = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
  return 2.0 * std::atan2(v, std::abs(d.w)) * 180.0 / 3.14159265358979323846;
}

inline std::vector<hid::Report> generate(const MotionStream& stream, double seconds,
                                         const EmulatorParams& p = {}) {
  ReportGenerator gen(stream, p);
  std::vector<hid::Report> out;
  while (gen.timeOfNextSampleSec() <= seconds) out.push_back(gen.next());
  return out;
}

struct Pipeline {
  hid::ReportParser parser;
  Fusion fusion;
  std::vector<FusedSample> out;
  void feed(std::span<const uint8_t> bytes) {
    std::vector<hid::ImuSample> samples;
    parser.parse(bytes, &samples);
    for (const auto& s : samples)
      if (fusion.update(s)) out.push_back(fusion.state());
  }
};

inline bool finite(const FusedSample& s) {
  const auto& q = s.orientation;
  const auto& w = s.angularVelocityRadPerSec;
  return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) &&
         std::isfinite(w.x) && std::isfinite(w.y) && std::isfinite(w.z) &&
         std::isfinite(s.headSpeedDegPerSec) && std::abs(glm::length(q) - 1.0) < 1e-6;
}

}  // namespace steadyxr::imu::test
