// Pose-curve derivatives, band-limited random processes and the involuntary head jitter.
#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "motion_internal.h"

namespace steadyxr::imu::detail {
namespace {

// One second-order section (RBJ Audio EQ Cookbook low/high-pass), direct form I.
struct Biquad {
  double b0 = 1, b1 = 0, b2 = 0, a1 = 0, a2 = 0;
  double x1 = 0, x2 = 0, y1 = 0, y2 = 0;
  static Biquad make(bool highPass, double cutoffHz, double sampleHz, double q) {
    const double w0 = 2.0 * std::numbers::pi * cutoffHz / sampleHz;
    const double c = std::cos(w0), alpha = std::sin(w0) / (2.0 * q), a0 = 1.0 + alpha;
    Biquad f;
    if (highPass) {
      f.b0 = f.b2 = (1.0 + c) / 2.0 / a0;
      f.b1 = -(1.0 + c) / a0;
    } else {
      f.b0 = f.b2 = (1.0 - c) / 2.0 / a0;
      f.b1 = (1.0 - c) / a0;
    }
    f.a1 = -2.0 * c / a0;
    f.a2 = (1.0 - alpha) / a0;
    return f;
  }
  double step(double x) {
    const double y = b0 * x + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2;
    x2 = x1, x1 = x, y2 = y1, y1 = y;
    return y;
  }
};

}  // namespace

dquat fromRotationVector(const dvec3& v) {
  const double angle = glm::length(v);
  if (angle < 1e-12) return glm::normalize(dquat(1.0, 0.5 * v.x, 0.5 * v.y, 0.5 * v.z));
  return glm::angleAxis(angle, v / angle);
}

dvec3 toRotationVector(dquat q) {
  if (q.w < 0.0) q = -q;
  const dvec3 xyz(q.x, q.y, q.z);
  const double s = glm::length(xyz);
  if (s < 1e-15) return 2.0 * xyz;
  return xyz * (2.0 * std::atan2(s, q.w) / s);
}

MotionState PoseStream::at(double t) const {
  t = std::max(t, 0.0);
  const double h = derivativeStep();
  const Pose p0 = poseAt(t - h);
  const Pose p1 = poseAt(t);
  const Pose p2 = poseAt(t + h);
  const dvec3 omega = toRotationVector(glm::conjugate(p0.q) * p2.q) / (2.0 * h);
  const double ha = std::max(h, 1e-3);  // second differences need a coarser step
  const dvec3 accel = (poseAt(t + ha).p - 2.0 * p1.p + poseAt(t - ha).p) / (ha * ha);
  MotionState s;
  s.orientation = glm::quat(glm::normalize(p1.q));
  s.angularVelocityRadPerSec = glm::vec3(omega);
  s.position = glm::vec3(p1.p);
  s.linearAccelerationMps2 = glm::vec3(accel);
  return s;
}

BandNoise::BandNoise(Rng& rng, double gridHz, double periodSec, double loHz, double hiHz, int sections)
    : gridHz_(gridHz) {
  const size_t n = std::max<size_t>(16, static_cast<size_t>(std::ceil(periodSec * gridHz)));
  std::vector<double> white(n);
  for (double& w : white) w = rng.gaussian();
  // Butterworth of order 2*sections as cascaded biquads: pole angles (2k-1)pi/(4 sections).
  std::vector<Biquad> chain;
  double slowestDecay = 2.0 * std::numbers::pi * hiHz;  // per second, of the slowest pole
  for (int k = 1; k <= sections; ++k) {
    const double theta = (2.0 * k - 1.0) * std::numbers::pi / (4.0 * sections);
    const double q = 1.0 / (2.0 * std::cos(theta));
    chain.push_back(Biquad::make(false, hiHz, gridHz, q));
    if (loHz > 0.0) chain.push_back(Biquad::make(true, loHz, gridHz, q));
    const double f = loHz > 0.0 ? loHz : hiHz;
    slowestDecay = std::min(slowestDecay, 2.0 * std::numbers::pi * f * std::cos(theta));
  }
  // Circular filtering: run over the periodic input until the transient is below e^-15.
  const int passes = 1 + static_cast<int>(std::ceil(15.0 / (slowestDecay * n / gridHz)));
  v_.assign(n, 0.0);
  for (int pass = 0; pass < passes; ++pass)
    for (size_t i = 0; i < n; ++i) {
      double x = white[i];
      for (Biquad& b : chain) x = b.step(x);
      v_[i] = x;
    }
  double sum2 = 0.0, d2 = 0.0;
  for (size_t i = 0; i < n; ++i) {
    sum2 += v_[i] * v_[i];
    const double d = (v_[(i + 1) % n] - v_[(i + n - 1) % n]) * gridHz / 2.0;
    d2 += d * d;
  }
  const double rms = std::sqrt(sum2 / n);
  for (double& v : v_) v /= rms;
  derivativeRms_ = std::sqrt(d2 / n) / rms;
}

double BandNoise::at(double t) const {
  if (v_.empty()) return 0.0;
  const auto n = static_cast<long long>(v_.size());
  const double x = t * gridHz_;
  const double fl = std::floor(x);
  const double f = x - fl;
  const long long i = ((static_cast<long long>(fl) % n) + n) % n;
  const double p0 = v_[(i + n - 1) % n], p1 = v_[i], p2 = v_[(i + 1) % n], p3 = v_[(i + 2) % n];
  // Catmull-Rom: passes through the samples, continuous first derivative.
  return p1 +
         0.5 * f * (p2 - p0 + f * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + f * (3.0 * (p1 - p2) + p3 - p0)));
}

Jitter::Jitter(const JitterParams& p, uint64_t seed) {
  Rng rng(seed ^ 0xF1A710ull);
  // Grids: 500 Hz resolves the tremor band (<= 12 Hz plus the filter skirts) smoothly; the
  // drift's period is at least 120 s so its 0.03 Hz floor is represented.
  for (int axis = 0; axis < 3; ++axis) {
    tremor_[axis] = BandNoise(rng, 500.0, std::max(p.periodSec, 10.0), p.tremorLowHz, p.tremorHighHz, 4);
    tremorScale_[axis] = p.tremorAmplitudeDeg;
    drift_[axis] = BandNoise(rng, 20.0, std::max(p.periodSec, 120.0), 0.03, 0.2, 2);
    driftScale_[axis] = std::abs(p.driftDegPerSec) / drift_[axis].derivativeRms();
    sway_[axis] = BandNoise(rng, 100.0, std::max(p.periodSec, 10.0), 0.5, 4.0, 2);
    swayScale_[axis] = p.translationTremorMm * 1e-3;
  }
  rotation0_ = raw(tremor_, tremorScale_, 0.0) + raw(drift_, driftScale_, 0.0);
  translation0_ = raw(sway_, swayScale_, 0.0);
}

dvec3 Jitter::raw(const BandNoise (&n)[3], const double (&scale)[3], double t) const {
  return {scale[0] * n[0].at(t), scale[1] * n[1].at(t), scale[2] * n[2].at(t)};
}

dvec3 Jitter::rotationDeg(double t) const {
  return raw(tremor_, tremorScale_, t) + raw(drift_, driftScale_, t) - rotation0_;
}

dvec3 Jitter::translation(double t) const {
  return raw(sway_, swayScale_, t) - translation0_;
}

double rampedTurnAngle(double t, double d, double rampIn, double rampOut, double v) {
  d = std::max(d, 1e-6);
  rampIn = std::clamp(rampIn, 0.0, d / 2.0);
  rampOut = std::clamp(rampOut, 0.0, d / 2.0);
  auto up = [&](double tau, double r) {  // angle covered tau seconds into a raised-cosine ramp
    if (r <= 0.0) return v * tau;
    return v * (tau / 2.0 - r / (2.0 * std::numbers::pi) * std::sin(std::numbers::pi * tau / r));
  };
  const double total = v * (d - rampIn / 2.0 - rampOut / 2.0);
  if (t <= 0.0) return 0.0;
  if (t >= d) return total;
  if (t < rampIn) return up(t, rampIn);
  if (t <= d - rampOut) return v * rampIn / 2.0 + v * (t - rampIn);
  return total - up(d - t, rampOut);
}

std::string formatText(const char* fmt, ...) {
  char buf[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, args);
  va_end(args);
  return buf;
}

}  // namespace steadyxr::imu::detail
