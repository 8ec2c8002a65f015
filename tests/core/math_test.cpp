// CPU math and params: checked against values worked out by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/quaternion.hpp>

#include "steadyxr/core/params.h"
#include "steadyxr/core/view_math.h"

using namespace steadyxr::core;

namespace {
constexpr float kPi = 3.14159265358979f;

glm::vec3 projectNdc(const glm::mat4& p, glm::vec3 v) {
  const glm::vec4 c = p * glm::vec4(v, 1.0f);
  return glm::vec3(c) / c.w;
}
}  // namespace

TEST(ViewMath, SymmetricProjectionMapsFovEdgesToNdcEdges) {
  const Fov fov;  // +-45 degrees: tan = 1
  const glm::mat4 p = projectionFromFov(fov, 0.1f, 100.0f);
  EXPECT_NEAR(projectNdc(p, {1, 0, -1}).x, 1.0f, 1e-5f);   // right edge
  EXPECT_NEAR(projectNdc(p, {0, 1, -1}).y, -1.0f, 1e-5f);  // up is -1 in Vulkan NDC
  EXPECT_NEAR(projectNdc(p, {0, 0, -0.1f}).z, 0.0f, 1e-5f);
  EXPECT_NEAR(projectNdc(p, {0, 0, -100.0f}).z, 1.0f, 1e-5f);
}

TEST(ViewMath, AsymmetricProjection) {
  // left -30 deg, right +45, up 20, down -40: tan l = -0.57735, r = 1, u = 0.36397, d = -0.83910.
  const Fov fov{-30 * kPi / 180, 45 * kPi / 180, 20 * kPi / 180, -40 * kPi / 180};
  const glm::mat4 p = projectionFromFov(fov, 0.05f, INFINITY);
  EXPECT_NEAR(projectNdc(p, {-0.57735f, 0, -1}).x, -1.0f, 1e-4f);
  EXPECT_NEAR(projectNdc(p, {1.0f, 0, -1}).x, 1.0f, 1e-4f);
  EXPECT_NEAR(projectNdc(p, {0, 0.36397f, -1}).y, -1.0f, 1e-4f);
  EXPECT_NEAR(projectNdc(p, {0, -0.83910f, -1}).y, 1.0f, 1e-4f);
  // straight ahead: x = (0 - l)/(r - l)*2 - 1 = 0.57735/1.57735*2 - 1 = -0.26795
  EXPECT_NEAR(projectNdc(p, {0, 0, -1}).x, -0.26795f, 1e-4f);
  EXPECT_NEAR(projectNdc(p, {0, 0, -0.05f}).z, 0.0f, 1e-5f);
  EXPECT_NEAR(projectNdc(p, {0, 0, -1e7f}).z, 1.0f, 1e-5f);  // infinite far plane
}

TEST(ViewMath, ViewFromPoseInvertsThePose) {
  Pose pose;
  pose.orientation = glm::angleAxis(kPi / 2, glm::vec3(0, 1, 0));  // turned 90 deg left
  pose.position = {1, 2, 3};
  const glm::mat4 v = viewFromPose(pose);
  // The eye looks along world -X now; a point 1 m along -X from the eye is straight ahead.
  const glm::vec4 ahead = v * glm::vec4(0, 2, 3, 1);
  EXPECT_NEAR(ahead.x, 0.0f, 1e-5f);
  EXPECT_NEAR(ahead.y, 0.0f, 1e-5f);
  EXPECT_NEAR(ahead.z, -1.0f, 1e-5f);
}

TEST(ViewMath, SlerpAndAngle) {
  Pose a, b;
  b.orientation = glm::angleAxis(kPi / 3, glm::vec3(1, 0, 0));  // 60 deg
  b.position = {0.3f, 0, 0};
  const Pose m = interpolatePose(a, b, 0.5f);
  EXPECT_NEAR(angleBetweenDeg(a.orientation, m.orientation), 30.0f, 1e-3f);
  EXPECT_NEAR(m.position.x, 0.15f, 1e-6f);
  EXPECT_NEAR(angleBetweenDeg(a.orientation, interpolatePose(a, b, 2.0f / 3.0f).orientation), 40.0f, 1e-3f);
  EXPECT_NEAR(angleBetweenDeg(a.orientation, b.orientation), 60.0f, 1e-3f);
  EXPECT_NEAR(angleBetweenDeg(b.orientation, -b.orientation), 0.0f, 1e-2f);  // q and -q are one rotation
}

TEST(ViewMath, AngleIsExactForSmallAngles) {
  // Rotations by a known angle from several base orientations, against the analytic angle.
  const glm::quat bases[] = {glm::quat(1, 0, 0, 0), glm::angleAxis(0.65f, glm::normalize(glm::vec3(1, 2, 3))),
                             glm::angleAxis(2.9f, glm::normalize(glm::vec3(-0.3f, 1, 0.2f)))};
  const glm::vec3 axes[] = {{0, 1, 0}, glm::normalize(glm::vec3(1, -1, 0.5f))};
  for (const glm::quat& base : bases)
    for (const glm::vec3& axis : axes)
      for (double deg : {0.001, 0.005, 0.02, 0.04, 0.1, 1.0, 10.0, 90.0, 179.0}) {
        const glm::quat b = base * glm::quat(glm::angleAxis(glm::radians(deg), glm::dvec3(axis)));
        // Float inputs: each component is rounded by ~6e-8, ~0.7e-5 deg of angle.
        EXPECT_NEAR(angleBetweenDeg(base, b), deg, 2e-5 + 1e-6 * deg) << deg;
        EXPECT_NEAR(angleBetweenDeg(b, base), deg, 2e-5 + 1e-6 * deg) << deg;
      }
  // Head speed from two frames 1/90 s apart: no steps (the acos form moved in ~1.2 deg/s steps
  // and read 0 below ~3.6 deg/s).
  const glm::quat a = bases[1];
  for (double speed = 0.1; speed < 5.0; speed += 0.05) {
    const glm::quat b = a * glm::quat(glm::angleAxis(glm::radians(speed / 90.0), glm::dvec3(0, 1, 0)));
    EXPECT_NEAR(angleBetweenDeg(a, b) * 90.0, speed, 0.002 + 1e-3 * speed) << speed;
  }
}

TEST(ViewMath, GlobalWeightAMatchesEq4) {
  EXPECT_NEAR(globalWeightA(0.0f, 25.0f, 0.3f), 0.3f, 1e-6f);
  // h = h_max/2: cos(pi/2) = 0 -> (-(0-1)/2)^2 = 0.25 -> 0.7*0.25 + 0.3 = 0.475
  EXPECT_NEAR(globalWeightA(12.5f, 25.0f, 0.3f), 0.475f, 1e-6f);
  // h = h_max/4: cos(pi/4) = 0.70711 -> (0.146447)^2 = 0.0214466 -> 0.7*0.0214466 + 0.3 = 0.315013
  EXPECT_NEAR(globalWeightA(6.25f, 25.0f, 0.3f), 0.315013f, 1e-5f);
  EXPECT_NEAR(globalWeightA(25.0f, 25.0f, 0.3f), 1.0f, 1e-6f);
  EXPECT_EQ(globalWeightA(25.1f, 25.0f, 0.3f), 1.0f);
  EXPECT_EQ(globalWeightA(NAN, 25.0f, 0.3f), 1.0f);
}

TEST(ViewMath, LocalisedWMinMatchesEq5) {
  EXPECT_NEAR(localisedWMin(0.3f, 0.1f, 0.0f), 0.3f, 1e-7f);
  EXPECT_NEAR(localisedWMin(0.3f, 0.1f, 1.0f), 0.1f, 1e-7f);
  EXPECT_NEAR(localisedWMin(0.3f, 0.1f, 0.25f), 0.25f, 1e-7f);  // 0.3 - 0.2*0.25
}

TEST(ViewMath, SampleWeightsSumToOneAndFavourRecent) {
  float w[4];
  const float one = 2.0f / 3.0f;
  sampleWeightsW(&one, 1, w);
  EXPECT_FLOAT_EQ(w[0], 1.0f);
  const float d[3] = {2.0f / 3.0f, 1.0f / 3.0f, 0.0f};
  sampleWeightsW(d, 3, w);
  // proportional to 1 + d: 5/3, 4/3, 1 over 4 -> 5/12, 4/12, 3/12
  EXPECT_NEAR(w[0], 5.0f / 12.0f, 1e-6f);
  EXPECT_NEAR(w[1], 4.0f / 12.0f, 1e-6f);
  EXPECT_NEAR(w[2], 3.0f / 12.0f, 1e-6f);
}

TEST(Params, MethodNamesRoundTrip) {
  for (const char* name : {"none", "fxaa", "taa", "hmtaa", "vtaa", "hybrid", "stereo", "taa+stereo",
                           "hybrid+stereo", "fxaa+stereo"}) {
    const auto p = applyMethodName(name);
    ASSERT_TRUE(p) << name;
    EXPECT_EQ(methodName(*p), name);
  }
  const auto def = applyMethodName("default");
  ASSERT_TRUE(def);
  EXPECT_EQ(def->temporal, kDefaultTemporalMethod);
  EXPECT_EQ(def->stereo, kDefaultStereo);
  EXPECT_FALSE(applyMethodName("bogus"));
  EXPECT_FALSE(applyMethodName("+stereo"));
  EXPECT_EQ(parseTemporalMethod("vtaa"), TemporalMethod::Vtaa);
}

TEST(Params, ValidateReportsAndSanitises) {
  EXPECT_EQ(validate(Params{}), "");
  Params bad;
  bad.wMin = NAN;
  bad.sampleCount = 9;
  bad.taaAlpha = -1.0f;
  Params fixed;
  const std::string msg = validate(bad, &fixed);
  EXPECT_NE(msg.find("taaAlpha"), std::string::npos) << msg;
  EXPECT_EQ(fixed.wMin, Params{}.wMin);
  EXPECT_EQ(fixed.sampleCount, Params{}.sampleCount);
  EXPECT_EQ(fixed.taaAlpha, Params{}.taaAlpha);
  EXPECT_EQ(validate(fixed), "");
}
