// Additions beside the motion.h contract: fast-turn defaults, the neck model and a ground-truth writer.
#pragma once

#include <string>

#include "steadyxr/imu/motion.h"

namespace steadyxr::imu {

// A default-constructed TurnParams passed to makeFastTurn() is replaced by these (200 deg/s,
// 0.6 s, 0.15 s ramps: a 90 deg head turn).
TurnParams fastTurnDefaults();

// Vector from the neck pivot to the point between the eyes, head frame (m): the pivot sits
// 7 cm below and 7 cm behind the eyes, so rotations also translate the eyes (disocclusion).
inline constexpr double kNeckToEyesY = 0.07;
inline constexpr double kNeckToEyesZ = -0.07;

// Writes the stream sampled at rateHz over [0, durationSec] as a trace CSV that loadTrace() reads:
//   t_s,qw,qx,qy,qz,wx,wy,wz,px,py,pz
bool writeTrace(const MotionStream& stream, double rateHz, double durationSec, const std::string& path,
                std::string* error);

}  // namespace steadyxr::imu
