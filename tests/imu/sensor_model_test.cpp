// The emulator's consumer-MEMS sensor model, read back from the report bytes it emits.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "imu_test_util.h"
#include "steadyxr/imu/emulator.h"
#include "steadyxr/imu/hid_report.h"
#include "steadyxr/imu/motion.h"

using namespace steadyxr::imu;

namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr double kGravity = 9.80665;

// A head held perfectly still: no tremor, drift, jumps or translation.
std::unique_ptr<MotionStream> stillHead(double seconds) {
  FixationParams p;
  p.durationSec = seconds;
  p.tremorAmplitudeDeg = 0.0;
  p.driftDegPerSec = 0.0;
  p.jumpsPerSec = 0.0;
  p.translationTremorMm = 0.0;
  return makeFixation(p, 1);
}

// Every sample's six values in SI units, decoded from the report bytes.
std::vector<std::array<double, 6>> decodeAll(const std::vector<hid::Report>& reports) {
  std::vector<std::array<double, 6>> out;
  for (const auto& r : reports) {
    hid::RawReport raw;
    EXPECT_EQ(hid::decode(r, &raw), hid::DecodeStatus::kOk);
    for (const auto& s : raw.samples) {
      std::array<double, 6> v;
      for (int k = 0; k < 6; ++k) v[k] = s[k] * (k < 3 ? hid::kGyroLsb : hid::kAccelLsb);
      out.push_back(v);
    }
  }
  return out;
}

struct MeanStd {
  double mean = 0, std = 0;
};
MeanStd stats(const std::vector<std::array<double, 6>>& v, int k) {
  double s = 0, s2 = 0;
  for (const auto& x : v) s += x[k], s2 += x[k] * x[k];
  const double n = double(v.size());
  return {s / n, std::sqrt(std::max(0.0, s2 / n - (s / n) * (s / n)))};
}

}  // namespace

TEST(SensorModel, ReportedNoiseMatchesTheDatasheetDensityAtTheSampleRate) {
  const auto still = stillHead(20.0);
  const SensorModel model;  // the defaults: BMI160 figures
  for (double rate : {1000.0, 250.0}) {
    EmulatorParams p;
    p.sampleRateHz = rate;
    p.seed = 3;
    const auto samples = decodeAll(test::generate(*still, 20.0, p));
    // sigma per sample = density * sqrt(rate), plus the 1e-3 quantisation step (LSB^2/12).
    const double gyroSigma = std::hypot(model.gyroNoiseDensityDegPerSecRtHz * kDegToRad * std::sqrt(rate),
                                        hid::kGyroLsb / std::sqrt(12.0));
    const double accelSigma = std::hypot(model.accelNoiseDensityUgRtHz * 1e-6 * kGravity * std::sqrt(rate),
                                         hid::kAccelLsb / std::sqrt(12.0));
    for (int k = 0; k < 3; ++k) {
      const MeanStd g = stats(samples, k), a = stats(samples, 3 + k);
      std::printf("%.0f Hz axis %d: gyro std %.5f rad/s (model %.5f), accel std %.4f m/s^2 (model %.4f)\n",
                  rate, k, g.std, gyroSigma, a.std, accelSigma);
      EXPECT_NEAR(g.std / gyroSigma, 1.0, 0.04) << rate << " " << k;
      EXPECT_NEAR(a.std / accelSigma, 1.0, 0.04) << rate << " " << k;
      // The means are the start-up biases: within 4 sigma of the model's spread.
      EXPECT_LT(std::abs(g.mean), 4.0 * model.gyroBiasSigmaDegPerSec * kDegToRad + 1e-3);
      const double gravity = k == 1 ? kGravity : 0.0;
      EXPECT_LT(std::abs(a.mean - gravity), 4.0 * model.accelBiasSigmaMg * 1e-3 * kGravity + 1e-3);
    }
  }
}

TEST(SensorModel, OffGivesTheExactQuantisedValues) {
  std::string error;
  const auto turn = makePreset("fastturn", 2, &error);
  ASSERT_TRUE(turn) << error;
  EmulatorParams p;
  p.sensor.enabled = false;
  ReportGenerator gen(*turn, p);
  EXPECT_EQ(gen.sensorErrors(), nullptr);
  for (int r = 0; r < 150; ++r) {
    const double t0 = gen.timeOfNextSampleSec();
    hid::RawReport raw;
    ASSERT_EQ(hid::decode(gen.next(), &raw), hid::DecodeStatus::kOk);
    for (size_t i = 0; i < hid::kSamplesPerReport; ++i) {
      const MotionState m = turn->at(t0 + double(i) * 1e-3);
      const glm::dvec3 f = glm::conjugate(glm::dquat(m.orientation)) *
                           (glm::dvec3(m.linearAccelerationMps2) + glm::dvec3(0.0, kGravity, 0.0));
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(raw.samples[i][k], hid::quantize(m.angularVelocityRadPerSec[k], hid::kGyroLsb));
        EXPECT_EQ(raw.samples[i][3 + k], hid::quantize(f[k], hid::kAccelLsb));
      }
    }
  }
}

TEST(SensorModel, SeededBiasesAndTheirRandomWalk) {
  const auto still = stillHead(1.0);
  EmulatorParams a, b, c;
  b.seed = a.seed;
  c.seed = a.seed + 1;
  EXPECT_EQ(test::generate(*still, 1.0, a), test::generate(*still, 1.0, b));
  EXPECT_NE(test::generate(*still, 1.0, a), test::generate(*still, 1.0, c));

  // Across devices (seeds): the start-up biases have the model's spread, and after T seconds the
  // gyro bias has wandered by K * sqrt(T) (a random walk), K the model's bias random walk.
  const SensorModel model;
  const double rate = 100.0, seconds = 100.0;
  double start2 = 0.0, walk2 = 0.0, accel2 = 0.0;
  int n = 0;
  for (uint64_t seed = 1; seed <= 300; ++seed) {
    SensorErrors e(model, rate, seed);
    const glm::dvec3 b0 = e.gyroBiasRadPerSec();
    const glm::dvec3 ab = e.accelBiasMps2();
    glm::dvec3 g(0.0), f(0.0);
    for (int i = 0; i < int(rate * seconds); ++i) e.apply(&g, &f);
    const glm::dvec3 d = e.gyroBiasRadPerSec() - b0;
    start2 += glm::dot(b0, b0);
    walk2 += glm::dot(d, d);
    accel2 += glm::dot(ab, ab);
    n += 3;
  }
  const double startSigma = std::sqrt(start2 / n) / kDegToRad;
  const double walkSigma = std::sqrt(walk2 / n) / kDegToRad;
  const double accelSigmaMg = std::sqrt(accel2 / n) / kGravity * 1e3;
  std::printf("900 axes: start-up gyro bias %.4f deg/s, wander in %.0f s %.5f deg/s, accel bias %.2f mg\n",
              startSigma, seconds, walkSigma, accelSigmaMg);
  EXPECT_NEAR(startSigma / model.gyroBiasSigmaDegPerSec, 1.0, 0.1);
  EXPECT_NEAR(walkSigma / (model.gyroBiasRandomWalkDegPerSecRtSec * std::sqrt(seconds)), 1.0, 0.1);
  EXPECT_NEAR(accelSigmaMg / model.accelBiasSigmaMg, 1.0, 0.1);
}
