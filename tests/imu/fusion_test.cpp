// Emulator -> report bytes -> parser -> fusion against the simulated ground truth.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>

#include "../../imu/src/rng.h"
#include "imu_test_util.h"
#include "steadyxr/imu/motion_extra.h"

using namespace steadyxr::imu;
using steadyxr::imu::test::angleDeg;

namespace {

struct Errors {
  double maxDeg = 0, atEndDeg = 0;
};

// Orientation error of the fused samples against the truth over [fromSec, toSec].
Errors compare(const MotionStream& truth, const std::vector<FusedSample>& fused, int64_t t0Ns, double fromSec,
               double toSec) {
  Errors e;
  for (const auto& f : fused) {
    const double t = static_cast<double>(f.timeNs - t0Ns) * 1e-9;
    if (t < fromSec || t > toSec) continue;
    const double err = angleDeg(f.orientation, glm::dquat(truth.at(t).orientation));
    e.maxDeg = std::max(e.maxDeg, err);
    e.atEndDeg = err;
  }
  return e;
}

// The sensor model off: quantisation only (the noiseless figures, beside the model's).
EmulatorParams exact() {
  EmulatorParams p;
  p.sensor.enabled = false;
  return p;
}

std::vector<FusedSample> run(const MotionStream& m, double seconds, const EmulatorParams& p) {
  test::Pipeline pipe;
  for (const auto& r : test::generate(m, seconds, p)) pipe.feed(r);
  return pipe.out;
}

}  // namespace

TEST(Fusion, RecoversFixationTremorOver10s) {
  double worst = 0;
  for (uint64_t seed : {1, 2, 3}) {
    const auto m = makeFixation({}, seed);
    const auto fused = run(*m, 10.0, exact());
    ASSERT_GE(fused.size(), 10000u);
    // The first seconds are the tilt estimate settling (a head is never still: its linear
    // acceleration, 0.1-0.2 m/s^2 from tremor about the neck, averages out only over time).
    const Errors all = compare(*m, fused, 0, 0.0, 10.0);
    const Errors early = compare(*m, fused, 0, 2.0, 10.0);
    const Errors settled = compare(*m, fused, 0, 5.0, 10.0);
    std::printf(
        "fixation seed %llu, no sensor noise: orientation error at 10 s %.4f deg, max over 5-10 s %.4f deg, "
        "over 2-10 s "
        "%.4f deg, over 0-10 s (incl. the initial tilt from one accelerometer sample) %.3f deg\n",
        static_cast<unsigned long long>(seed), settled.atEndDeg, settled.maxDeg, early.maxDeg, all.maxDeg);
    EXPECT_LE(early.maxDeg, 0.1);
    EXPECT_LE(settled.atEndDeg, 0.05);
    EXPECT_LE(settled.maxDeg, 0.05);
    worst = std::max(worst, settled.maxDeg);
  }
  RecordProperty("fixation_max_error_deg", std::to_string(worst));
}

namespace {
// A turn as a user makes it: after holding still for 5 s (the filter has settled).
constexpr double kHoldSec = 5.0;
std::unique_ptr<MotionStream> afterFixation(std::unique_ptr<MotionStream> turn, uint64_t seed) {
  FixationParams hold;
  hold.durationSec = kHoldSec;
  std::vector<std::unique_ptr<MotionStream>> parts;
  parts.push_back(makeFixation(hold, seed));
  parts.push_back(std::move(turn));
  return makeSequence(std::move(parts));
}
}  // namespace

TEST(Fusion, TracksAFastTurnAndMeasuresHeadSpeed) {
  const TurnParams p = fastTurnDefaults();  // 200 deg/s plateau, 90 deg
  const auto m = afterFixation(makeFastTurn(p, 1), 1);
  const auto fused = run(*m, m->durationSec(), exact());
  const Errors before = compare(*m, fused, 0, kHoldSec - 0.1, kHoldSec);
  const Errors e = compare(*m, fused, 0, kHoldSec, m->durationSec());
  double speedErr = 0;
  for (const auto& f : fused) {  // plateau, after the smoothing has settled (5 time constants)
    const double t = static_cast<double>(f.timeNs) * 1e-9 - kHoldSec;
    if (t > p.rampSec + 0.15 && t < p.durationSec - p.rampSec)
      speedErr = std::max(speedErr, std::abs(f.headSpeedDegPerSec - 200.0) / 200.0);
  }
  std::printf(
      "fast turn 200 deg/s (90 deg), no sensor noise: max orientation error during the turn %.4f deg (%.4f "
      "deg before it), "
      "plateau speed error %.3f %%\n",
      e.maxDeg, before.maxDeg, speedErr * 100);
  EXPECT_LE(e.maxDeg, 0.05);
  EXPECT_LE(speedErr, 0.05);
  RecordProperty("fastturn_max_error_deg", std::to_string(e.maxDeg));
}

TEST(Fusion, HeadSpeedOnASteadyPursuit) {
  const auto m = afterFixation(makePursuit({}, 1), 2);  // 20 deg/s for 3 s
  const auto fused = run(*m, m->durationSec(), exact());
  double speedErr = 0;
  for (const auto& f : fused) {
    const double t = static_cast<double>(f.timeNs) * 1e-9 - kHoldSec;
    if (t > 0.5 && t < 2.7) speedErr = std::max(speedErr, std::abs(f.headSpeedDegPerSec - 20.0) / 20.0);
  }
  const Errors e = compare(*m, fused, 0, kHoldSec, m->durationSec());
  std::printf(
      "pursuit 20 deg/s, no sensor noise: plateau speed error %.3f %%, max orientation error %.4f deg\n",
      speedErr * 100, e.maxDeg);
  EXPECT_LE(speedErr, 0.05);
  EXPECT_LE(e.maxDeg, 0.05);
}

TEST(Fusion, TiltCorrectionAndBiasEstimateWithANoisyBiasedGyro) {
  // A gyro bias about a horizontal axis: the accelerometer holds the tilt and the integral term
  // learns the bias. (Yaw bias would stay: no magnetometer.)
  FixationParams fp;
  fp.durationSec = 30.0;
  const auto m = makeFixation(fp, 4);
  EmulatorParams p = exact();                  // this test's own, larger errors instead of the model's
  p.gyroBiasRadPerSec = {0.002f, 0.0f, 0.0f};  // 0.11 deg/s about x (pitch)
  p.gyroNoiseRadPerSec = 0.005;
  p.accelNoiseMps2 = 0.05;
  test::Pipeline pipe;
  for (const auto& r : test::generate(*m, 30.0, p)) pipe.feed(r);
  const Errors at10 = compare(*m, pipe.out, 0, 9.9, 10.0);
  const Errors at30 = compare(*m, pipe.out, 0, 29.0, 30.0);
  const glm::dvec3 bias = pipe.fusion.gyroBias();
  std::printf(
      "fixation with 0.11 deg/s pitch bias + noise: error at 10 s %.4f deg, max over 29-30 s %.4f deg, "
      "estimated bias x %.5f rad/s (true 0.002)\n",
      at10.atEndDeg, at30.maxDeg, bias.x);
  EXPECT_LT(at10.atEndDeg, 0.3);  // without tilt correction: 1.1 deg
  EXPECT_LT(at30.maxDeg, 0.1);
  EXPECT_NEAR(bias.x, 0.002, 0.0003);
}

namespace {
// Tilt error: angle between the true and the fused "up" in the head frame.
double tiltErrorDeg(const glm::dquat& fused, const glm::dquat& truth) {
  const glm::dvec3 a = glm::conjugate(fused) * glm::dvec3(0, 1, 0),
                   b = glm::conjugate(truth) * glm::dvec3(0, 1, 0);
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) * 180.0 / 3.14159265358979323846;
}
}  // namespace

TEST(Fusion, AccuracyWithTheSensorModel) {
  // With the consumer-MEMS model on (the default), what remains is what no fusion without a
  // reference can remove: a tilt of (horizontal accelerometer bias)/g and a yaw drift of the yaw
  // gyro bias times the time since start. The fusion must stay within those plus 0.1 deg (its
  // own error without noise is up to 0.06 deg in the first seconds, see above). When
  // the head turns, the head-frame bias turns with it while the estimate follows at the filter's
  // 0.5 /s: up to twice the bias's tilt for a while.
  // The motions of the tests above (same seeds), so the figures sit beside the noiseless ones.
  struct Case {
    const char* what;
    std::unique_ptr<MotionStream> m;
    double from, tiltFactor;
    double plateauDegPerSec = 0.0, plateauFrom = 0.0, plateauTo = 0.0;  // head speed check
  };
  std::vector<Case> cases;
  for (uint64_t seed : {1, 2, 3}) cases.push_back({"fixation", makeFixation({}, seed), 5.0, 1.0});
  cases.push_back({"fast turn after 5 s", afterFixation(makeFastTurn(fastTurnDefaults(), 1), 1), kHoldSec,
                   2.0, 200.0, kHoldSec + 0.3, kHoldSec + 0.45});
  cases.push_back({"pursuit after 5 s", afterFixation(makePursuit({}, 1), 2), kHoldSec, 2.0, 20.0,
                   kHoldSec + 0.5, kHoldSec + 2.7});
  uint64_t seed = 10;
  for (const Case& c : cases) {
    EmulatorParams p;
    p.seed = ++seed;
    ReportGenerator gen(*c.m, p);
    test::Pipeline pipe;
    while (gen.timeOfNextSampleSec() <= c.m->durationSec()) pipe.feed(gen.next());
    const SensorErrors& sensor = *gen.sensorErrors();
    const glm::dvec3 ab = sensor.accelBiasMps2(), gb = sensor.gyroBiasRadPerSec();
    const double tiltBound =
        c.tiltFactor * std::atan(std::hypot(ab.x, ab.z) / 9.80665) * 180.0 / 3.14159265358979323846;
    const double yawBound = std::abs(gb.y) * c.m->durationSec() * 180.0 / 3.14159265358979323846;
    double maxTilt = 0.0, maxErr = 0.0, speedErr = 0.0;
    for (const auto& f : pipe.out) {
      const double t = static_cast<double>(f.timeNs) * 1e-9;
      if (t < c.from) continue;
      const glm::dquat truth(c.m->at(t).orientation);
      maxTilt = std::max(maxTilt, tiltErrorDeg(f.orientation, truth));
      maxErr = std::max(maxErr, angleDeg(f.orientation, truth));
      if (t > c.plateauFrom && t < c.plateauTo)
        speedErr = std::max(speedErr, std::abs(f.headSpeedDegPerSec / c.plateauDegPerSec - 1.0));
    }
    std::printf(
        "%s with the sensor model (seed %llu): max error from %.0f s %.3f deg, at the end %.3f deg (tilt "
        "%.3f deg; bounds: accel bias tilt %.3f, yaw bias drift %.3f deg), plateau speed error %.3f %%\n",
        c.what, static_cast<unsigned long long>(p.seed), c.from, maxErr,
        angleDeg(pipe.out.back().orientation, glm::dquat(c.m->at(pipe.out.back().timeNs * 1e-9).orientation)),
        maxTilt, tiltBound, yawBound, speedErr * 100.0);
    EXPECT_LE(maxTilt, tiltBound + 0.1) << c.what;
    EXPECT_LE(maxErr, tiltBound + yawBound + 0.1) << c.what;
    EXPECT_LE(speedErr, 0.05) << c.what;
  }
}

TEST(Fusion, DroppedReportsAndClockJumpsKeepTheOutputContinuous) {
  std::string error;
  const auto m = makePreset("sequence", 21, &error);
  auto reports = test::generate(*m, m->durationSec(), {});
  test::Pipeline pipe;
  steadyxr::imu::detail::Rng rng(5);
  for (size_t i = 0; i < reports.size(); ++i) {
    if (rng.uniform() < 0.1) continue;  // 10 % dropped
    auto r = reports[i];
    if (i % 500 == 250) r[8] ^= 0x40;  // a device clock jump of ~1.07e9 us
    if (i % 700 == 350) r[6] ^= 0x80;  // small backwards/forwards step of 32 ms
    pipe.feed(r);
  }
  ASSERT_GT(pipe.out.size(), 7000u);
  double maxStep = 0;
  for (size_t i = 1; i < pipe.out.size(); ++i) {
    ASSERT_TRUE(test::finite(pipe.out[i]));
    ASSERT_GT(pipe.out[i].timeNs, pipe.out[i - 1].timeNs);
    const double dt = static_cast<double>(pipe.out[i].timeNs - pipe.out[i - 1].timeNs) * 1e-9;
    ASSERT_LE(dt, 0.05);  // the time line never jumps
    maxStep = std::max(maxStep, angleDeg(pipe.out[i].orientation, pipe.out[i - 1].orientation) / (dt * 1000));
  }
  // From 2 s: the first is the tilt estimate settling from one accelerometer sample (as in
  // RecoversFixationTremorOver10s), which drops and clock jumps have nothing to do with.
  const Errors e = compare(*m, pipe.out, 0, 2.0, m->durationSec());
  std::printf(
      "sequence with 10%% drops and clock jumps: max error over 2 s-end %.3f deg, max step %.3f deg/ms\n",
      e.maxDeg, maxStep);
  EXPECT_LT(maxStep, 0.25);  // <= 200 deg/s head speed: no jumps
  EXPECT_LT(e.maxDeg, 0.5);
  EXPECT_GT(pipe.parser.stats().timestampJumps + pipe.parser.stats().timestampBackwards, 10u);
}

TEST(PoseHistory, InterpolatesPredictsAndRefuses) {
  PoseHistory h;
  EXPECT_FALSE(h.stateAt(0));
  std::vector<FusedSample> s(3);
  for (int i = 0; i < 3; ++i) {
    s[i].timeNs = 1'000'000'000 + i * 1'000'000;
    s[i].orientation = glm::angleAxis(0.001 * i, glm::dvec3(0, 1, 0));  // 1 rad/s yaw
    s[i].angularVelocityRadPerSec = {0, 1, 0};
    s[i].headSpeedDegPerSec = 57.3;
  }
  h.push(s);
  h.push(std::span(s).first(1));  // old: refused
  EXPECT_EQ(h.outOfOrder(), 1u);
  const auto mid = h.stateAt(1'001'500'000);
  ASSERT_TRUE(mid);
  EXPECT_FALSE(mid->predicted);
  EXPECT_NEAR(angleDeg(glm::dquat(1, 0, 0, 0), glm::dquat(mid->orientation)), 0.0015 * 57.29578, 1e-4);
  const auto ahead = h.stateAt(1'022'000'000);  // 20 ms beyond: predicted with constant velocity
  ASSERT_TRUE(ahead);
  EXPECT_TRUE(ahead->predicted);
  EXPECT_NEAR(angleDeg(glm::dquat(1, 0, 0, 0), glm::dquat(ahead->orientation)), 0.022 * 57.29578, 1e-3);
  EXPECT_FALSE(h.stateAt(1'200'000'000));  // too far ahead
  EXPECT_FALSE(h.stateAt(999'000'000));    // before the history
}

TEST(PoseHistory, ConcurrentReadersWhileAWriterPushes) {
  PoseHistory::Params params;
  params.capacity = 256;  // wraps many times
  PoseHistory h(params);
  std::atomic<bool> done{false};
  std::atomic<uint64_t> answers{0}, bad{0};
  std::vector<std::thread> readers;
  for (int r = 0; r < 2; ++r)
    readers.emplace_back([&] {
      while (!done) {
        const auto newest = h.newestTimeNs();
        if (!newest) continue;
        for (int64_t off : {-100'000'000, -50'500'000, -1'000, 0, 5'000'000}) {
          if (const auto st = h.stateAt(*newest + off)) {
            ++answers;
            const glm::quat& q = st->orientation;
            if (!std::isfinite(q.w) || std::abs(glm::length(q) - 1.0f) > 1e-4f) ++bad;
          }
        }
      }
    });
  for (int i = 0; i < 20000; ++i) {
    if (i % 100 == 0) std::this_thread::sleep_for(std::chrono::microseconds(200));  // let readers in
    FusedSample s;
    s.timeNs = int64_t(i) * 1'000'000;
    s.orientation = glm::angleAxis(0.001 * i, glm::dvec3(0, 1, 0));
    s.angularVelocityRadPerSec = {0, 1, 0};
    h.push(std::span(&s, 1));
  }
  done = true;
  for (auto& t : readers) t.join();
  EXPECT_GT(answers.load(), 0u);
  EXPECT_EQ(bad.load(), 0u);
  EXPECT_EQ(h.size(), 256u);
}

TEST(ClockMapper, TracksMinimumLatencyAndResetsOnJumps) {
  ClockMapper c;
  c.update(1'000'000'000, 0);  // 1 s offset plus some latency
  c.update(1'001'000'000 + 300'000, 1'000'000);
  EXPECT_NEAR(c.toHost(0), 1'000'000'000, 1'000);  // the lower-latency sample wins; slow creep
  c.update(1'002'000'000 - 200'000, 2'000'000);    // even less latency
  EXPECT_EQ(c.toHost(0), 1'000'000'000 - 200'000);
  c.update(9'000'000'000, 3'000'000);  // host suspended, or device restarted
  EXPECT_EQ(c.resets(), 1u);
  EXPECT_EQ(c.toHost(3'000'000), 9'000'000'000);
}
