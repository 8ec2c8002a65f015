#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include "imu_test_util.h"
#include "steadyxr/imu/motion.h"
#include "steadyxr/imu/motion_extra.h"

using namespace steadyxr::imu;
using steadyxr::imu::test::angleDeg;

namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("steadyxr_imu_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

}  // namespace

TEST(Motion, DeterministicForASeed) {
  const auto a = makeFixation({}, 42), b = makeFixation({}, 42), c = makeFixation({}, 43);
  for (double t : {0.0, 0.37, 2.5, 9.9}) {
    EXPECT_EQ(a->at(t).orientation, b->at(t).orientation);
    EXPECT_EQ(a->at(t).position, b->at(t).position);
  }
  EXPECT_GT(angleDeg(glm::dquat(a->at(5.0).orientation), glm::dquat(c->at(5.0).orientation)), 1e-4);
}

TEST(Motion, FixationTremorHasTheConfiguredAmplitudeAndBand) {
  FixationParams p;
  p.driftDegPerSec = 0.0;
  p.jumpsPerSec = 0.0;
  p.tremorAmplitudeDeg = 0.05;
  const auto s = makeFixation(p, 7);
  // RMS of the yaw angle (about its mean) and of its rate: rate/angle ~ 2*pi*f, so f lies in the band.
  double sum = 0, sum2 = 0, rate2 = 0;
  const int n = 10000;
  for (int i = 0; i < n; ++i) {
    const MotionState m = s->at(i * 1e-3);
    const glm::dvec3 rv =
        glm::axis(glm::dquat(m.orientation)) * double(glm::angle(glm::dquat(m.orientation)));
    sum += rv.y * kRadToDeg;
    sum2 += rv.y * rv.y * kRadToDeg * kRadToDeg;
    rate2 += m.angularVelocityRadPerSec.y * m.angularVelocityRadPerSec.y * kRadToDeg * kRadToDeg;
  }
  const double rms = std::sqrt(sum2 / n - (sum / n) * (sum / n));
  const double f = std::sqrt(rate2 / n) / rms / (2.0 * 3.14159265358979323846);
  EXPECT_NEAR(rms, 0.05, 0.015);
  EXPECT_GT(f, 8.0);
  EXPECT_LT(f, 12.0);
  // Translational tremor: sub-millimetre, plus the neck coupling of the tiny rotations.
  for (int i = 0; i < 100; ++i) EXPECT_LT(glm::length(s->at(i * 0.1).position), 2e-3f);
}

TEST(Motion, AngularVelocityIsTheDerivativeOfTheOrientation) {
  // Integrating the reported angular velocity reproduces the orientation: what a gyro would see.
  for (const char* name : {"fixation", "fastturn", "sequence"}) {
    std::string error;
    const auto s = makePreset(name, 3, &error);
    ASSERT_TRUE(s) << error;
    glm::dquat q(s->at(0.0).orientation);
    const double dt = 1e-4;
    double maxErr = 0;
    glm::dvec3 wPrev(s->at(0.0).angularVelocityRadPerSec);
    for (double t = dt; t <= s->durationSec(); t += dt) {
      const glm::dvec3 w(s->at(t).angularVelocityRadPerSec);
      const glm::dvec3 r = 0.5 * (w + wPrev) * dt;
      const double a = glm::length(r);
      if (a > 0) q = glm::normalize(q * glm::angleAxis(a, r / a));
      wPrev = w;
      maxErr = std::max(maxErr, angleDeg(q, glm::dquat(s->at(t).orientation)));
    }
    EXPECT_LT(maxErr, 0.01) << name;
  }
}

TEST(Motion, TurnsHaveTheirSpeedsAndANeckPivotTranslation) {
  const auto pursuit = makePursuit({}, 1);
  EXPECT_NEAR(glm::length(pursuit->at(1.5).angularVelocityRadPerSec) * kRadToDeg, 20.0, 0.01);
  const auto fast = makeFastTurn({}, 1);  // default params: the fast turn defaults
  EXPECT_NEAR(glm::length(fast->at(0.3).angularVelocityRadPerSec) * kRadToDeg, 200.0, 0.05);
  const double total =
      angleDeg(glm::dquat(fast->at(0).orientation), glm::dquat(fast->at(fast->durationSec()).orientation));
  EXPECT_NEAR(total, 90.0, 0.01);
  // A 90 deg yaw about a pivot 7 cm behind the eyes moves them by 7 cm * sqrt(2) sideways/back.
  EXPECT_NEAR(glm::length(fast->at(fast->durationSec()).position), 0.07 * std::sqrt(2.0), 1e-4);
  EXPECT_NEAR(fast->at(fast->durationSec()).position.y, 0.0, 1e-6);
  // Smooth start: no speed at t = 0.
  EXPECT_LT(glm::length(fast->at(0.0).angularVelocityRadPerSec), 1e-3);
}

TEST(Motion, SequenceIsContinuousAcrossSegments) {
  std::string error;
  const auto s = makePreset("sequence", 5, &error);
  ASSERT_TRUE(s) << error;
  double maxStep = 0, maxPosStep = 0;
  for (double t = 0; t < s->durationSec(); t += 1e-3) {
    const MotionState a = s->at(t), b = s->at(t + 1e-3);
    maxStep = std::max(maxStep, angleDeg(glm::dquat(a.orientation), glm::dquat(b.orientation)));
    maxPosStep = std::max(maxPosStep, double(glm::length(a.position - b.position)));
  }
  EXPECT_LT(maxStep, 0.25);       // at most 200 deg/s * 1 ms
  EXPECT_LT(maxPosStep, 0.5e-3);  // at most ~0.25 m/s * 1 ms
  EXPECT_NEAR(s->durationSec(), 2 + 2 + 2 + 0.6 + 2, 1e-9);
}

TEST(Motion, TraceRoundTripAndAngularVelocityOnlyTraces) {
  std::string error;
  const auto truth = makePreset("sequence", 9, &error);
  const std::string path = tempPath("trace.csv");
  ASSERT_TRUE(writeTrace(*truth, 1000.0, truth->durationSec(), path, &error)) << error;
  const auto replay = loadTrace(path, &error);
  ASSERT_TRUE(replay) << error;
  EXPECT_NEAR(replay->durationSec(), truth->durationSec(), 1e-3);
  double maxErr = 0, maxPos = 0;
  for (double t = 0.0005; t < truth->durationSec(); t += 0.0137) {
    maxErr = std::max(maxErr,
                      angleDeg(glm::dquat(truth->at(t).orientation), glm::dquat(replay->at(t).orientation)));
    maxPos = std::max(maxPos, double(glm::length(truth->at(t).position - replay->at(t).position)));
  }
  EXPECT_LT(maxErr, 1e-3);
  EXPECT_LT(maxPos, 1e-5);

  // Angular velocity only: integrated on load.
  const std::string wpath = tempPath("wtrace.csv");
  {
    std::ofstream f(wpath);
    f << "t_s,wx,wy,wz\n";
    for (int i = 0; i <= 1000; ++i) f << i * 1e-3 << ",0,0.5,0\n";  // 0.5 rad/s yaw for 1 s
  }
  const auto w = loadTrace(wpath, &error);
  ASSERT_TRUE(w) << error;
  EXPECT_NEAR(angleDeg(glm::dquat(1, 0, 0, 0), glm::dquat(w->at(1.0).orientation)), 0.5 * kRadToDeg, 1e-3);
  EXPECT_NEAR(w->at(0.5).angularVelocityRadPerSec.y, 0.5f, 1e-6);
  std::filesystem::remove(path);
  std::filesystem::remove(wpath);
}

TEST(Motion, TracesGiveTheirAngularVelocityColumnsAndTheirEnd) {
  // Orientation and wx,wy,wz that disagree on purpose: a recorded gyro is not the difference of
  // two recorded poses (those quantise and lag); the columns are the head speed when present.
  const std::string path = tempPath("qw_trace.csv");
  {
    std::ofstream f(path);
    f << "t_s,qw,qx,qy,qz,wx,wy,wz\n";
    for (int i = 0; i <= 100; ++i) {  // 1 s at 100 Hz: 10 deg/s yaw in the poses, 0.3 rad/s pitch in w
      const glm::dquat q = glm::angleAxis(10.0 / kRadToDeg * i * 0.01, glm::dvec3(0, 1, 0));
      f << i * 0.01 << "," << q.w << "," << q.x << "," << q.y << "," << q.z << ",0.3,0,0\n";
    }
  }
  std::string error;
  const auto s = loadTrace(path, &error);
  ASSERT_TRUE(s) << error;
  EXPECT_NEAR(s->at(0.505).angularVelocityRadPerSec.x, 0.3f, 1e-6);
  EXPECT_NEAR(s->at(0.505).angularVelocityRadPerSec.y, 0.0f, 1e-6);
  EXPECT_NEAR(s->headSpeedDegPerSec(0.505), 0.3 * kRadToDeg, 1e-4);
  EXPECT_NEAR(s->validUntilSec(), 1.0, 1e-9);  // callers check a run against it
  // Without the columns: the poses' derivative, 10 deg/s.
  const std::string qpath = tempPath("q_trace.csv");
  {
    std::ofstream f(qpath);
    f << "t_s,qw,qx,qy,qz\n";
    for (int i = 0; i <= 100; ++i) {
      const glm::dquat q = glm::angleAxis(10.0 / kRadToDeg * i * 0.01, glm::dvec3(0, 1, 0));
      f << i * 0.01 << "," << q.w << "," << q.x << "," << q.y << "," << q.z << "\n";
    }
  }
  const auto q = loadTrace(qpath, &error);
  ASSERT_TRUE(q) << error;
  EXPECT_NEAR(q->headSpeedDegPerSec(0.505), 10.0, 0.01);
  // A sequence ends where its last part does; generators never end.
  std::vector<std::unique_ptr<MotionStream>> parts;
  parts.push_back(makeFixation({}, 1));
  parts.push_back(loadTrace(path, &error));
  EXPECT_NEAR(makeSequence(std::move(parts))->validUntilSec(), 11.0, 1e-9);
  EXPECT_TRUE(std::isinf(makeFixation({}, 1)->validUntilSec()));
  std::filesystem::remove(path);
  std::filesystem::remove(qpath);
}

TEST(Motion, MalformedTracesAndUnknownPresetsAreErrors) {
  std::string error;
  EXPECT_FALSE(loadTrace("/nonexistent/trace.csv", &error));
  EXPECT_NE(error.find("cannot open"), std::string::npos);
  const std::string path = tempPath("bad.csv");
  for (const char* body : {"t_s,qw,qx\n0,1,0\n", "t_s,qw,qx,qy,qz\n0,1,0,0,0\n0,1,0,0,0\n",
                           "t_s,qw,qx,qy,qz\n0,1,0,0,0\n0.1,abc,0,0,0\n", "", "t_s,wx,wy,wz\n0,0,0,0\n"}) {
    std::ofstream(path) << body;
    error.clear();
    EXPECT_FALSE(loadTrace(path, &error)) << body;
    EXPECT_FALSE(error.empty());
  }
  std::filesystem::remove(path);
  EXPECT_FALSE(makePreset("wobble", 1, &error));
  EXPECT_NE(error.find("unknown"), std::string::npos);
}
