// The app's rig motion under --locomotion (eval/locomotion.h), checked against what a player's
// stick does: expectations written from the geometry (a yaw about the vertical through the head,
// a walk along the level view axes), not from the code.
#include "locomotion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

namespace steadyxr::eval {
namespace {

constexpr float kDegToRad = float(std::numbers::pi / 180.0);

Locomotion parsed(const std::string& spec) {
  Locomotion l;
  std::string error;
  EXPECT_TRUE(parseLocomotion(spec, &l, &error)) << spec << ": " << error;
  return l;
}

// Signed yaw (degrees, left > 0) from the tracked view's forward to the rigged one's, on the floor.
float yawBetweenDeg(const HeadPose& from, const HeadPose& to) {
  const glm::vec3 a = from.orientation * glm::vec3(0, 0, -1), b = to.orientation * glm::vec3(0, 0, -1);
  return std::atan2(a.z * b.x - a.x * b.z, a.x * b.x + a.z * b.z) / kDegToRad;
}

TEST(EvalLocomotion, ReadsEveryKindAndRefusesTheRest) {
  EXPECT_EQ(parsed("turn:45").kind, LocomotionKind::Turn);
  EXPECT_EQ(parsed("turn:-45").amount, -45.0);
  EXPECT_EQ(parsed("strafe:1.5").kind, LocomotionKind::Strafe);
  EXPECT_EQ(parsed("forward:2").amount, 2.0);
  EXPECT_EQ(parsed("snap:30").kind, LocomotionKind::Snap);
  EXPECT_EQ(parsed("none").kind, LocomotionKind::None);
  EXPECT_EQ(parsed("").kind, LocomotionKind::None);
  EXPECT_EQ(toString(parsed("strafe:1.5")), "strafe:1.5");
  for (const std::string bad : {"jump:1", "turn", "turn:", "turn:fast", "turn:30x", "turn:0", "turn:nan",
                                "turn:1000", "snap:200", "forward:50"}) {
    Locomotion l;
    std::string error;
    EXPECT_FALSE(parseLocomotion(bad, &l, &error)) << bad;
    EXPECT_NE(error.find(bad), std::string::npos) << "the message names what was given: " << error;
    EXPECT_EQ(l.kind, LocomotionKind::None) << "a refused spec leaves no rig motion";
  }
}

TEST(EvalLocomotion, ASmoothTurnYawsAboutTheHeadOnlyWhileTheStickIsHeld) {
  const Locomotion l = parsed("turn:40");
  RigSchedule s;
  s.runSec = 2.0;  // the stick is held from 0.5 s to 1.5 s
  s.start.position = glm::vec3(0.3f, 1.6f, -0.2f);
  HeadPose tracked = s.start;
  tracked.orientation = glm::angleAxis(10.0f * kDegToRad, glm::vec3(1, 0, 0));  // a pitched head
  for (const auto& [t, yaw] :
       {std::pair{0.0, 0.0f}, {0.49, 0.0f}, {1.0, 20.0f}, {1.5, 40.0f}, {1.9, 40.0f}}) {
    const HeadPose rigged = rigPose(l, s, tracked, t);
    EXPECT_NEAR(yawBetweenDeg(tracked, rigged), yaw, 1e-3) << "t " << t;
    // The pitch is the head's: a turn about the vertical keeps the view's elevation.
    const glm::vec3 a = tracked.orientation * glm::vec3(0, 0, -1),
                    b = rigged.orientation * glm::vec3(0, 0, -1);
    EXPECT_NEAR(a.y, b.y, 1e-5) << "t " << t;
    EXPECT_NEAR(glm::length(rigged.position - s.start.position), 0.0f, 1e-6) << "a turn on the spot";
  }
  // A head leaned 0.1 m to the right of where the run began swings with the turn: after 90 degrees
  // to the left it is 0.1 m ahead (-z) of the pivot.
  const Locomotion quarter = parsed("turn:90");
  RigSchedule one{1.0, HeadPose{}, 1.0};  // held from 0.25 s to 0.75 s: 45 degrees
  HeadPose leaned;
  leaned.position = glm::vec3(0.1f, 0.0f, 0.0f);
  const float c = std::cos(45.0f * kDegToRad);
  const glm::vec3 p = rigPose(quarter, one, leaned, 0.8).position;
  EXPECT_NEAR(p.x, 0.1f * c, 1e-5);
  EXPECT_NEAR(p.z, -0.1f * c, 1e-5);
}

TEST(EvalLocomotion, AWalkFollowsTheStartViewsLevelAxes) {
  RigSchedule s;
  s.runSec = 1.0;
  s.translationScale = 2.0;  // --ppd's depth scale: metres of the stretched scene
  // Turned 90 degrees to the left (facing -x) and looking 30 degrees down: ahead on the floor is
  // -x, to the right is -z.
  s.start.orientation = glm::angleAxis(90.0f * kDegToRad, glm::vec3(0, 1, 0)) *
                        glm::angleAxis(-30.0f * kDegToRad, glm::vec3(1, 0, 0));
  const HeadPose tracked = s.start;
  const glm::vec3 strafed = rigPose(parsed("strafe:1"), s, tracked, 0.75).position;  // 0.5 s at 2 m/s
  EXPECT_NEAR(strafed.x, 0.0f, 1e-5);
  EXPECT_NEAR(strafed.y, 0.0f, 1e-5);
  EXPECT_NEAR(strafed.z, -1.0f, 1e-5);
  const glm::vec3 walked = rigPose(parsed("forward:1"), s, tracked, 0.5).position;  // 0.25 s
  EXPECT_NEAR(walked.x, -0.5f, 1e-5);
  EXPECT_NEAR(walked.y, 0.0f, 1e-5);
  EXPECT_NEAR(walked.z, 0.0f, 1e-5);
  EXPECT_NEAR(yawBetweenDeg(tracked, rigPose(parsed("forward:1"), s, tracked, 0.5)), 0.0f, 1e-4);
  EXPECT_EQ(locomotionChangeTimes(parsed("forward:1"), s), (std::vector<double>{0.25, 0.75}));
}

TEST(EvalLocomotion, ASnapTurnsForTheMiddleThirdAndBack) {
  const Locomotion l = parsed("snap:-30");
  const RigSchedule s{3.0, HeadPose{}, 1.0};
  const HeadPose head;
  EXPECT_NEAR(yawBetweenDeg(head, rigPose(l, s, head, 0.99)), 0.0f, 1e-4);
  EXPECT_NEAR(yawBetweenDeg(head, rigPose(l, s, head, 1.0)), -30.0f, 1e-3);
  EXPECT_NEAR(yawBetweenDeg(head, rigPose(l, s, head, 1.99)), -30.0f, 1e-3);
  EXPECT_NEAR(yawBetweenDeg(head, rigPose(l, s, head, 2.0)), 0.0f, 1e-4);
  EXPECT_EQ(locomotionChangeTimes(l, s), (std::vector<double>{1.0, 2.0}));
  EXPECT_TRUE(locomotionChangeTimes(parsed("none"), s).empty());
  EXPECT_FALSE(rigMoves(parsed("none")));
}

}  // namespace
}  // namespace steadyxr::eval
