// Artificial locomotion's rig motion (locomotion.h).
#include "locomotion.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include <glm/gtc/quaternion.hpp>

namespace steadyxr::eval {

namespace {

struct KindName {
  LocomotionKind kind;
  const char* name;
  double maxAmount;  // beyond any game's setting: refused as a typo
};
// Games offer smooth turns up to about 180 deg/s, snaps up to 90 deg, and walks up to a run.
constexpr KindName kKinds[] = {{LocomotionKind::Turn, "turn", 360.0},
                               {LocomotionKind::Strafe, "strafe", 10.0},
                               {LocomotionKind::Forward, "forward", 10.0},
                               {LocomotionKind::Snap, "snap", 180.0}};

// The schedule (locomotion.h), as fractions of the run: the stick's press and release, the snap and back.
constexpr double kStickOn = 1.0 / 4.0, kStickOff = 3.0 / 4.0;
constexpr double kSnapTurn = 1.0 / 3.0, kSnapBack = 2.0 / 3.0;

// Seconds the stick has been held at t.
double secondsMoved(const RigSchedule& s, double t) {
  return std::clamp(t, kStickOn * s.runSec, kStickOff * s.runSec) - kStickOn * s.runSec;
}

}  // namespace

bool parseLocomotion(const std::string& spec, Locomotion* out, std::string* error) {
  *out = Locomotion{};
  if (spec.empty() || spec == "none") return true;
  const auto colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const KindName* found = nullptr;
  for (const KindName& k : kKinds) {
    if (kind == k.name) found = &k;
  }
  if (found == nullptr) {
    *error = "--locomotion '" + spec + "': unknown kind '" + kind + "' (turn:DEG_PER_S, strafe:M_PER_S, " +
             "forward:M_PER_S, snap:DEG or none)";
    return false;
  }
  const std::string value = colon == std::string::npos ? std::string() : spec.substr(colon + 1);
  char* end = nullptr;
  const double amount = value.empty() ? NAN : std::strtod(value.c_str(), &end);
  if (!std::isfinite(amount) || end == nullptr || *end != '\0' || amount == 0.0 ||
      std::fabs(amount) > found->maxAmount) {
    *error = "--locomotion '" + spec + "': " + kind + " needs a non-zero amount of at most " +
             std::to_string(int(found->maxAmount)) +
             (found->kind == LocomotionKind::Turn   ? " deg/s"
              : found->kind == LocomotionKind::Snap ? " deg"
                                                    : " m/s") +
             " after the colon, e.g. " + kind + ":" +
             (found->kind == LocomotionKind::Snap || found->kind == LocomotionKind::Turn ? "30" : "1");
    return false;
  }
  out->kind = found->kind;
  out->amount = amount;
  return true;
}

std::string toString(const Locomotion& l) {
  for (const KindName& k : kKinds) {
    if (k.kind == l.kind) {
      char amount[32];
      std::snprintf(amount, sizeof(amount), "%g", l.amount);
      std::string s = k.name;
      s += ':';
      s += amount;
      return s;
    }
  }
  return "none";
}

bool rigMoves(const Locomotion& l) {
  return l.kind != LocomotionKind::None && l.amount != 0.0;
}

HeadPose rigPose(const Locomotion& l, const RigSchedule& s, const HeadPose& tracked, double t) {
  if (l.kind == LocomotionKind::None) return tracked;
  float yawDeg = 0.0f;
  glm::vec3 walk(0.0f);
  // The start view's level axes: a walk keeps to the floor whatever the head's pitch.
  const glm::vec3 ahead = s.start.orientation * glm::vec3(0, 0, -1);
  const glm::vec3 forward = glm::length(glm::vec2(ahead.x, ahead.z)) > 1e-6f
                                ? glm::normalize(glm::vec3(ahead.x, 0.0f, ahead.z))
                                : glm::vec3(0, 0, -1);
  const glm::vec3 right = glm::cross(forward, glm::vec3(0, 1, 0));
  const float metres = float(l.amount * s.translationScale * secondsMoved(s, t));
  switch (l.kind) {
    case LocomotionKind::None:
      break;
    case LocomotionKind::Turn:
      yawDeg = float(l.amount * secondsMoved(s, t));
      break;
    case LocomotionKind::Strafe:
      walk = right * metres;
      break;
    case LocomotionKind::Forward:
      walk = forward * metres;
      break;
    case LocomotionKind::Snap:
      yawDeg = t >= kSnapTurn * s.runSec && t < kSnapBack * s.runSec ? float(l.amount) : 0.0f;
      break;
  }
  const glm::quat yaw = glm::angleAxis(glm::radians(yawDeg), glm::vec3(0, 1, 0));
  HeadPose out;
  out.orientation = glm::normalize(yaw * tracked.orientation);
  out.position = s.start.position + yaw * (tracked.position - s.start.position) + walk;
  return out;
}

std::vector<double> locomotionChangeTimes(const Locomotion& l, const RigSchedule& s) {
  if (!rigMoves(l)) return {};
  if (l.kind == LocomotionKind::Snap) return {kSnapTurn * s.runSec, kSnapBack * s.runSec};
  return {kStickOn * s.runSec, kStickOff * s.runSec};
}

}  // namespace steadyxr::eval
