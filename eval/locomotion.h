// Artificial locomotion: the app moves the player's virtual rig (a thumbstick's smooth turn or
// walk, a snap turn) and renders from the rig's pose, but the pose it submits in xrEndFrame is
// the tracked head's in its reference space, as OpenXR asks (the runtime's timewarp needs it).
// So the layer sees a still head while the whole picture moves. `--locomotion` runs every case
// under one such rig motion: the truth and every method's input are rendered from the rigged
// pose; the filters are told the tracked one.
#pragma once

#include "eye_rig.h"

#include <string>
#include <vector>

namespace steadyxr::eval {

enum class LocomotionKind { None, Turn, Strafe, Forward, Snap };

struct Locomotion {
  LocomotionKind kind = LocomotionKind::None;
  // turn: deg/s of yaw (left for > 0); strafe, forward: m/s (right, ahead); snap: deg of yaw.
  double amount = 0.0;
};

// "turn:30", "strafe:1", "forward:1", "snap:30", or "none" / "" for no rig motion. False with
// *error in the user's words for anything else (an unknown kind, a missing or non-finite amount,
// an amount beyond what a game's settings offer).
bool parseLocomotion(const std::string& spec, Locomotion* out, std::string* error);
std::string toString(const Locomotion& l);  // the spec parseLocomotion reads back

// When in a run of `runSec` seconds (from the first frame) the rig moves. A stick is held for the
// middle half of the run (a step in velocity, as games apply it: on at runSec/4, off at
// 3 runSec/4); a snap turns at runSec/3 and back at 2 runSec/3.
struct RigSchedule {
  double runSec = 0.0;
  HeadPose start;                 // the tracked head at the first frame: the pivot and the walk's axes
  double translationScale = 1.0;  // --ppd: 1/tangent scale, as the scenes' depths (scene.h)
};

// The pose the app renders from at run time t (seconds since the first frame), given the tracked
// head: the rig's yaw about the world's up axis through the start position, then its walk along
// the start view's level right or forward axis.
HeadPose rigPose(const Locomotion& l, const RigSchedule& s, const HeadPose& tracked, double runSec);
// Run times at which the rig's motion changes (the stick pressed or released, a snap): the
// recovery target's motion changes.
std::vector<double> locomotionChangeTimes(const Locomotion& l, const RigSchedule& s);
// True when the rig moves at some time of the run (such a case is not a still head's).
bool rigMoves(const Locomotion& l);

}  // namespace steadyxr::eval
