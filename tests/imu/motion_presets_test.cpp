// The head-motion corpus: every preset seeded, and each one has the amplitudes, frequencies and
// motion changes its documentation (imu/src/motion_presets.cpp, imu/README.md) states.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "imu_test_util.h"
#include "steadyxr/imu/motion.h"

using namespace steadyxr::imu;
using steadyxr::imu::test::angleDeg;

namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;
constexpr double kRateHz = 1000.0;  // the IMU's sample rate

std::unique_ptr<MotionStream> preset(const std::string& name, uint64_t seed) {
  std::string error;
  auto s = makePreset(name, seed, &error);
  EXPECT_TRUE(s) << error;
  return s;
}

// |DFT|^2 of x at frequency f (Hz), samples at kRateHz.
double power(const std::vector<double>& x, double f) {
  std::complex<double> sum = 0.0;
  const double w = -2.0 * std::numbers::pi * f / kRateHz;
  for (size_t i = 0; i < x.size(); ++i) sum += x[i] * std::polar(1.0, w * double(i));
  return std::norm(sum);
}

// Fraction of the signal's variance (mean removed) between loHz and hiHz, from DFT bins.
double bandFraction(std::vector<double> x, double loHz, double hiHz) {
  double mean = 0.0;
  for (double v : x) mean += v / double(x.size());
  double total = 0.0;
  for (double& v : x) {
    v -= mean;
    total += v * v;
  }
  const double binHz = kRateHz / double(x.size());
  double band = 0.0;
  for (double f = std::ceil(loHz / binHz) * binHz; f <= hiHz + 1e-9; f += binHz) band += 2.0 * power(x, f);
  return band / (double(x.size()) * total);
}

// Frequency of the largest DFT bin of x between loHz and hiHz, in steps of stepHz.
double peakHz(const std::vector<double>& x, double loHz, double hiHz, double stepHz) {
  double best = 0.0, bestF = loHz;
  for (double f = loHz; f <= hiHz; f += stepHz)
    if (const double p = power(x, f); p > best) best = p, bestF = f;
  return bestF;
}

template <typename F>
std::vector<double> sample(const MotionStream& s, double from, double to, F&& value) {
  std::vector<double> out;
  for (double t = from; t < to; t += 1.0 / kRateHz) out.push_back(value(s.at(t)));
  return out;
}

double rms(const std::vector<double>& x) {
  double s = 0.0;
  for (double v : x) s += v * v;
  return std::sqrt(s / double(x.size()));
}

double peakToPeak(const std::vector<double>& x) {
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  return *hi - *lo;
}

std::vector<double> speedsDeg(const MotionStream& s, double from, double to) {
  return sample(s, from, to,
                [](const MotionState& m) { return glm::length(m.angularVelocityRadPerSec) * kRadToDeg; });
}

}  // namespace

TEST(MotionPresets, ListedPresetsExistAndEverySeedGivesAnotherMotion) {
  ASSERT_GE(motionPresets().size(), 10u);
  int corpus = 0;
  for (const MotionPreset& p : motionPresets()) {
    corpus += p.inCorpus;
    const auto a = preset(p.name, 1), b = preset(p.name, 1), c = preset(p.name, 2);
    ASSERT_TRUE(a && b && c) << p.name;
    EXPECT_FALSE(p.motionClass.empty() || p.summary.empty()) << p.name;
    double diff = 0.0;
    for (double t : {0.3, 1.1, 2.7}) {
      EXPECT_EQ(a->at(t).orientation, b->at(t).orientation) << p.name;  // deterministic for a seed
      EXPECT_EQ(a->at(t).position, b->at(t).position) << p.name;
      diff = std::max(diff, angleDeg(glm::dquat(a->at(t).orientation), glm::dquat(c->at(t).orientation)));
    }
    EXPECT_GT(diff, 1e-3) << p.name << ": the seed does not change it";
    const auto changes = a->motionChangeTimes();
    EXPECT_TRUE(std::is_sorted(changes.begin(), changes.end())) << p.name;
    for (double t : changes) EXPECT_TRUE(t >= 0.0 && t <= a->durationSec()) << p.name << " " << t;
    EXPECT_TRUE(std::isinf(a->validUntilSec())) << p.name;  // generators: defined for any time
  }
  EXPECT_GE(corpus, 10);
}

TEST(MotionPresets, AngularVelocityIsTheDerivativeOfTheOrientation) {
  for (const MotionPreset& p : motionPresets()) {
    const auto s = preset(p.name, 3);
    glm::dquat q(s->at(0.0).orientation);
    const double dt = 2e-4;
    double maxErr = 0;
    glm::dvec3 wPrev(s->at(0.0).angularVelocityRadPerSec);
    for (double t = dt; t <= std::min(3.0, s->durationSec()); t += dt) {
      const glm::dvec3 w(s->at(t).angularVelocityRadPerSec);
      const glm::dvec3 r = 0.5 * (w + wPrev) * dt;
      if (const double a = glm::length(r); a > 0) q = glm::normalize(q * glm::angleAxis(a, r / a));
      wPrev = w;
      maxErr = std::max(maxErr, angleDeg(q, glm::dquat(s->at(t).orientation)));
    }
    EXPECT_LT(maxErr, 0.01) << p.name;
  }
}

TEST(MotionPresets, TremorIsBandLimitedNoiseWithTheDocumentedAmplitudes) {
  const auto x1 = preset("tremor-1x", 5), x2 = preset("tremor-2x", 5), xh = preset("tremor-0.5x", 5);
  double speedRms[3];
  int i = 0;
  for (const auto* s : {xh.get(), x1.get(), x2.get()}) speedRms[i++] = rms(speedsDeg(*s, 0.0, 10.0));
  std::printf("tremor angular speed RMS: 0.5x %.3f, 1x %.3f, 2x %.3f deg/s\n", speedRms[0], speedRms[1],
              speedRms[2]);
  EXPECT_NEAR(speedRms[2] / speedRms[1], 2.0, 0.1);
  EXPECT_NEAR(speedRms[0] / speedRms[1], 0.5, 0.03);
  for (int axis = 0; axis < 3; ++axis) {
    // Angular velocity spectrum: most power in 8-12 Hz. 8th-order Butterworth edges at 8 and 12 Hz
    // with the f^2 of a derivative put 74 % there in expectation; the drift's share is ~0.5 %.
    const auto w = sample(*x1, 0.0, 10.0,
                          [&](const MotionState& m) { return double(m.angularVelocityRadPerSec[axis]); });
    const double inBand = bandFraction(w, 8.0, 12.0);
    std::printf("tremor-1x axis %d: %.1f %% of the angular-velocity power in 8-12 Hz\n", axis,
                100.0 * inBand);
    EXPECT_GT(inBand, 0.6) << axis;
  }
  // Angle RMS of the tremor: the 1x minus the 0.5x of the same seed is 0.5x of pure tremor
  // (drift and translation are the same in both and cancel).
  const auto diff = sample(*x1, 0.0, 10.0, [&, t = 0.0](const MotionState& m) mutable {
    const glm::dquat d = glm::conjugate(glm::dquat(xh->at(t).orientation)) * glm::dquat(m.orientation);
    t += 1.0 / kRateHz;
    return 2.0 * d.y * kRadToDeg;  // small angle about the yaw axis
  });
  EXPECT_NEAR(rms(diff), 0.5 * 0.02, 0.002);
}

TEST(MotionPresets, MicrosaccadesJumpByTheDocumentedSizesAndIntervals) {
  const auto s = preset("microsaccades", 7);
  const auto t = s->motionChangeTimes();
  ASSERT_GE(t.size(), 5u);
  EXPECT_GE(t.front(), 0.5 - 1e-9);
  EXPECT_LE(t.front(), 1.0 + 1e-9);
  for (size_t i = 1; i < t.size(); ++i) {
    EXPECT_GE(t[i] - t[i - 1], 0.5 - 1e-9);
    EXPECT_LE(t[i] - t[i - 1], 1.0 + 1e-9);
  }
  for (double tj : t) {
    // Over 50 ms around the jump: the jump (0.2-0.5 deg) plus a little tremor and drift.
    const double jump =
        angleDeg(glm::dquat(s->at(tj - 0.005).orientation), glm::dquat(s->at(tj + 0.045).orientation));
    EXPECT_GT(jump, 0.15) << tj;
    EXPECT_LT(jump, 0.56) << tj;
    // Fast: peak speed of a 0.2-0.5 deg smootherstep over 20-40 ms is 9-47 deg/s.
    const auto v = speedsDeg(*s, tj, tj + 0.04);
    EXPECT_GT(*std::max_element(v.begin(), v.end()), 7.0) << tj;
  }
}

TEST(MotionPresets, PursuitHoldStopsToTremorLevel) {
  for (uint64_t seed : {1, 2, 3}) {
    const auto s = preset("pursuit-hold", seed);
    const auto c = s->motionChangeTimes();
    ASSERT_EQ(c.size(), 2u);
    const auto moving = speedsDeg(*s, c[0] + 0.3, c[1] - 0.15);
    const double mid = moving[moving.size() / 2];
    EXPECT_GT(mid, 14.0);
    EXPECT_LT(mid, 31.0);
    // After the stop: the speed of tremor only (compare the tremor-1x preset's, same seed).
    auto held = speedsDeg(*s, c[1] + 0.05, s->durationSec());
    auto still = speedsDeg(*preset("tremor-1x", seed), 0.0, 10.0);
    std::sort(held.begin(), held.end());
    std::sort(still.begin(), still.end());
    const double p95Held = held[held.size() * 95 / 100], p95Still = still[still.size() * 95 / 100];
    std::printf("pursuit-hold seed %llu: %.1f deg/s, then 95th percentile %.2f deg/s (tremor-1x: %.2f)\n",
                static_cast<unsigned long long>(seed), mid, p95Held, p95Still);
    EXPECT_LT(p95Held, 1.5 * p95Still);
    EXPECT_GT(p95Held, 0.5 * p95Still);
  }
}

TEST(MotionPresets, PursuitStopPursuitHasTwoPursuitsAndAStop) {
  const auto s = preset("pursuit-stop-pursuit", 4);
  const auto c = s->motionChangeTimes();
  ASSERT_EQ(c.size(), 4u);
  EXPECT_GE(c[2] - c[1], 0.4 - 1e-9);
  EXPECT_LE(c[2] - c[1], 0.8 + 1e-9);
  EXPECT_GT(s->headSpeedDegPerSec(0.5 * (c[0] + c[1])), 14.0);
  EXPECT_LT(s->headSpeedDegPerSec(0.5 * (c[1] + c[2])), 8.0);  // stopped: tremor only
  EXPECT_GT(s->headSpeedDegPerSec(0.5 * (c[2] + c[3])), 14.0);
}

TEST(MotionPresets, WalkBobsAtTheStepRate) {
  for (uint64_t seed : {1, 2}) {
    const auto s = preset("walk", seed);
    const auto y = sample(*s, 0.0, 8.0, [](const MotionState& m) { return double(m.position.y); });
    const auto x = sample(*s, 0.0, 8.0, [](const MotionState& m) { return double(m.position.x); });
    const double stepHz = peakHz(y, 1.0, 3.0, 0.02), strideHz = peakHz(x, 0.5, 1.5, 0.02);
    std::printf("walk seed %llu: vertical %.1f cm peak to peak at %.2f Hz, lateral %.1f cm at %.2f Hz\n",
                static_cast<unsigned long long>(seed), peakToPeak(y) * 100, stepHz, peakToPeak(x) * 100,
                strideHz);
    // Documented: 3-4 cm bob at 1.8-2 steps/s, 2-3 cm side sway at half that; the gait variability
    // (5 % amplitude) and the neck pivot's share of the 1-2 deg rotations widen the bounds a little.
    EXPECT_GT(peakToPeak(y), 0.027);
    EXPECT_LT(peakToPeak(y), 0.045);
    EXPECT_GE(stepHz, 1.76);
    EXPECT_LE(stepHz, 2.04);
    EXPECT_NEAR(strideHz, stepHz / 2.0, 0.05);
    EXPECT_GT(peakToPeak(x), 0.017);
    EXPECT_LT(peakToPeak(x), 0.036);
    double maxRot = 0.0;
    for (double t = 0.0; t < 8.0; t += 0.01)
      maxRot = std::max(maxRot, angleDeg(glm::dquat(1, 0, 0, 0), glm::dquat(s->at(t).orientation)));
    EXPECT_LT(maxRot, 3.5);  // small rotations only
  }
}

TEST(MotionPresets, LeanMovesTheHeadTenToTwentyCentimetres) {
  const auto s = preset("lean", 6);
  const auto c = s->motionChangeTimes();
  ASSERT_EQ(c.size(), 4u);
  const glm::dvec3 p0(s->at(c[0]).position), p1(s->at(c[1]).position), p2(s->at(c[3]).position);
  // Forward (-Z) and a little down; the neck pivot adds the pitch's share (<= 1.3 cm at 10 deg).
  EXPECT_LT(p1.z - p0.z, -0.09);
  EXPECT_GT(p1.z - p0.z, -0.22);
  EXPECT_GT(std::abs(p2.x - p1.x), 0.09);
  EXPECT_LT(std::abs(p2.x - p1.x), 0.22);
  const double pitch = angleDeg(glm::dquat(s->at(c[0]).orientation), glm::dquat(s->at(c[1]).orientation));
  EXPECT_GT(pitch, 4.5);
  EXPECT_LT(pitch, 10.5);
  // Still between the leans (tremor only).
  EXPECT_LT(s->headSpeedDegPerSec(0.5 * (c[1] + c[2])), 8.0);
}

TEST(MotionPresets, SwayIsSlowAndAFewDegrees) {
  const auto s = preset("sway", 8);
  const auto yaw = sample(*s, 0.0, 8.0, [](const MotionState& m) {
    const glm::dquat q(m.orientation);
    return glm::yaw(q) * kRadToDeg;
  });
  const double f = peakHz(yaw, 0.1, 1.0, 0.01);
  std::printf("sway: yaw %.1f deg peak to peak at %.2f Hz\n", peakToPeak(yaw), f);
  EXPECT_GT(peakToPeak(yaw), 3.5);
  EXPECT_LT(peakToPeak(yaw), 9.0);  // 4-8 deg documented, plus tremor and drift
  EXPECT_GE(f, 0.2);                // 0.25-0.35 Hz, resolved to 1/8 s over the 8 s window
  EXPECT_LE(f, 0.4);
}
