#include "steadyxr/imu/fusion.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace steadyxr::imu {
namespace {

constexpr double kGravity = 9.80665;
constexpr double kRadToDeg = 180.0 / std::numbers::pi;

glm::dquat expMap(const glm::dvec3& v) {  // rotation vector -> unit quaternion
  const double angle = glm::length(v);
  if (angle < 1e-12) return glm::normalize(glm::dquat(1.0, 0.5 * v.x, 0.5 * v.y, 0.5 * v.z));
  return glm::angleAxis(angle, v / angle);
}

// Shortest rotation taking unit vector a onto unit vector b.
glm::dquat rotationBetween(const glm::dvec3& a, const glm::dvec3& b) {
  const double c = glm::dot(a, b);
  if (c < -0.999999) return glm::angleAxis(3.14159265358979323846, glm::dvec3(1.0, 0.0, 0.0));
  const glm::dvec3 axis = glm::cross(a, b);
  return glm::normalize(glm::dquat(1.0 + c, axis.x, axis.y, axis.z));
}

bool finite(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

bool Fusion::update(const hid::ImuSample& s) {
  const glm::dvec3 rawGyro(s.gyroRadPerSec);
  const glm::dvec3 accel(s.accelMps2);
  if (!finite(rawGyro) || (initialized_ && s.deviceTimeNs <= state_.timeNs)) {
    ++rejected_;
    return false;
  }
  const glm::dvec3 gyro = rawGyro - gyroBias_;
  const double accelNorm = finite(accel) ? glm::length(accel) : 0.0;
  const bool accelUsable = s.accelValid && std::abs(accelNorm - kGravity) < p_.gateAccelErrorMps2;
  if (!initialized_) {
    // Tilt from the first usable accelerometer sample, yaw 0.
    const glm::dvec3 up(0.0, 1.0, 0.0);
    state_.orientation =
        accelUsable ? rotationBetween(accel / accelNorm, up) : glm::dquat(1.0, 0.0, 0.0, 0.0);
    state_.timeNs = s.deviceTimeNs;
    state_.angularVelocityRadPerSec = gyro;
    state_.headSpeedDegPerSec = glm::length(gyro) * kRadToDeg;
    startNs_ = s.deviceTimeNs;
    initialized_ = true;
    return true;
  }
  const double dt = static_cast<double>(s.deviceTimeNs - state_.timeNs) * 1e-9;
  const double step = std::min(dt, p_.maxStepSec);
  // Trapezoidal rule on the angular velocity: second order, matches the sampled truth well.
  glm::dquat q = state_.orientation * expMap(0.5 * (state_.angularVelocityRadPerSec + gyro) * step);

  if (accelUsable && glm::length(gyro) < p_.gateGyroRadPerSec) {
    const double sinceStart = static_cast<double>(s.deviceTimeNs - startNs_) * 1e-9;
    const double gain = std::clamp(1.0 / (sinceStart + 0.01), p_.tiltGainPerSec,
                                   std::max(p_.warmupGainPerSec, p_.tiltGainPerSec));
    // Low-pass the specific force in the world frame (where gravity is constant): the head's
    // linear acceleration (tremor, the neck lever arm) is mostly above 1 Hz and averages out.
    const glm::dvec3 worldAccel = q * accel;
    const double tau = std::min(p_.accelTimeConstantSec, sinceStart + step);
    worldAccelLp_ =
        haveLp_ ? worldAccelLp_ + (worldAccel - worldAccelLp_) * (1.0 - std::exp(-step / std::max(tau, 1e-6)))
                : worldAccel;
    haveLp_ = true;
    const double lpNorm = glm::length(worldAccelLp_);
    if (lpNorm > 1e-6) {
      // World-frame rotation that turns the measured up towards +Y.
      const glm::dvec3 err = glm::cross(worldAccelLp_ / lpNorm, glm::dvec3(0.0, 1.0, 0.0));
      const glm::dquat correction = expMap(err * std::min(gain * step, 1.0));
      q = correction * q;
      // Integral term (Mahony): a constant tilt error means a gyro bias; only once the start-up
      // gain has settled, so the initial tilt does not wind it up. Yaw bias stays unobservable.
      if (gain <= p_.tiltGainPerSec && p_.biasGainPerSec > 0.0) {
        gyroBias_ -= (glm::conjugate(q) * err) * (p_.biasGainPerSec * step);
        const double b = glm::length(gyroBias_);
        if (b > p_.maxBiasRadPerSec) gyroBias_ *= p_.maxBiasRadPerSec / b;
      }
      worldAccelLp_ = correction * worldAccelLp_;  // the stored mean turns with the estimate
    }
  }
  state_.orientation = glm::normalize(q);
  state_.timeNs = s.deviceTimeNs;
  state_.angularVelocityRadPerSec = gyro;
  const double alpha = 1.0 - std::exp(-step / std::max(p_.speedTimeConstantSec, 1e-6));
  state_.headSpeedDegPerSec += (glm::length(gyro) * kRadToDeg - state_.headSpeedDegPerSec) * alpha;
  return true;
}

PoseHistory::PoseHistory(const Params& p) : p_(p), ring_(std::max<size_t>(p.capacity, 2)) {}

void PoseHistory::push(std::span<const FusedSample> samples) {
  const std::lock_guard lock(mu_);
  for (const FusedSample& s : samples) {
    if (count_ > 0 && s.timeNs <= ring_[(head_ + count_ - 1) % ring_.size()].timeNs) {
      ++outOfOrder_;
      continue;
    }
    if (count_ == ring_.size()) {
      ring_[head_] = s;
      head_ = (head_ + 1) % ring_.size();
    } else {
      ring_[(head_ + count_) % ring_.size()] = s;
      ++count_;
    }
  }
}

std::optional<HeadState> PoseHistory::stateAt(int64_t timeNs) const {
  FusedSample a, b;
  {
    const std::lock_guard lock(mu_);
    if (count_ == 0) return std::nullopt;
    auto at = [&](size_t i) -> const FusedSample& { return ring_[(head_ + i) % ring_.size()]; };
    const FusedSample& oldest = at(0);
    const FusedSample& newest = at(count_ - 1);
    if (timeNs < oldest.timeNs - p_.maxBeforeOldestNs) return std::nullopt;
    if (timeNs >= newest.timeNs) {
      if (timeNs - newest.timeNs > p_.maxPredictNs) return std::nullopt;
      a = b = newest;
    } else if (timeNs <= oldest.timeNs) {
      a = b = oldest;
    } else {
      size_t lo = 0, hi = count_ - 1;  // at(lo).t <= t < at(hi).t
      while (hi - lo > 1) {
        const size_t mid = (lo + hi) / 2;
        (at(mid).timeNs <= timeNs ? lo : hi) = mid;
      }
      a = at(lo);
      b = at(hi);
    }
  }
  HeadState out;
  out.timeNs = timeNs;
  if (a.timeNs == b.timeNs) {
    // Constant angular velocity prediction beyond the newest sample.
    const double dt = static_cast<double>(timeNs - a.timeNs) * 1e-9;
    out.orientation = glm::quat(glm::normalize(a.orientation * expMap(a.angularVelocityRadPerSec * dt)));
    out.angularVelocityRadPerSec = glm::vec3(a.angularVelocityRadPerSec);
    out.headSpeedDegPerSec = static_cast<float>(a.headSpeedDegPerSec);
    out.predicted = timeNs > a.timeNs;
    return out;
  }
  const double f = static_cast<double>(timeNs - a.timeNs) / static_cast<double>(b.timeNs - a.timeNs);
  glm::dquat qb = b.orientation;
  if (glm::dot(a.orientation, qb) < 0.0) qb = -qb;
  out.orientation = glm::quat(glm::normalize(glm::slerp(a.orientation, qb, f)));
  out.angularVelocityRadPerSec =
      glm::vec3(glm::mix(a.angularVelocityRadPerSec, b.angularVelocityRadPerSec, f));
  out.headSpeedDegPerSec =
      static_cast<float>(a.headSpeedDegPerSec + (b.headSpeedDegPerSec - a.headSpeedDegPerSec) * f);
  return out;
}

size_t PoseHistory::size() const {
  const std::lock_guard lock(mu_);
  return count_;
}

std::optional<int64_t> PoseHistory::newestTimeNs() const {
  const std::lock_guard lock(mu_);
  if (count_ == 0) return std::nullopt;
  return ring_[(head_ + count_ - 1) % ring_.size()].timeNs;
}

uint64_t PoseHistory::outOfOrder() const {
  const std::lock_guard lock(mu_);
  return outOfOrder_;
}

int64_t ClockMapper::update(int64_t hostReceiveNs, int64_t deviceNs) {
  const int64_t candidate = hostReceiveNs - deviceNs;
  constexpr int64_t kResetNs = 200'000'000;  // 200 ms off: not latency any more
  if (!valid_ || std::abs(candidate - offset_) > kResetNs) {
    if (valid_) ++resets_;
    offset_ = candidate;
    valid_ = true;
  } else if (candidate < offset_) {
    offset_ = candidate;  // less latency than ever seen: the better estimate
  } else {
    // Creep up by at most 200 ppm of elapsed host time, to follow a device clock that is slow.
    const int64_t elapsed = std::max<int64_t>(hostReceiveNs - lastHostNs_, 0);
    offset_ += std::min(candidate - offset_, elapsed / 5000);
  }
  lastHostNs_ = hostReceiveNs;
  return offset_;
}

}  // namespace steadyxr::imu
