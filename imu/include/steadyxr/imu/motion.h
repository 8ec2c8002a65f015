// Simulated head motion: the ground truth that the IMU emulator turns into HID reports and that
// the evaluation harness renders scenes from. Deterministic for a given seed.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

namespace steadyxr::imu {

struct MotionState {
  glm::quat orientation{1.0f, 0.0f, 0.0f, 0.0f};  // head-to-world, OpenXR axes
  glm::vec3 angularVelocityRadPerSec{0.0f};       // head frame (what a head-mounted gyro measures)
  glm::vec3 position{0.0f};                       // metres, head centre in world (translation, tremor)
  glm::vec3 linearAccelerationMps2{0.0f};         // world frame, excluding gravity
};

class MotionStream {
 public:
  virtual ~MotionStream() = default;
  virtual MotionState at(double tSec) const = 0;  // any t >= 0; continuous in t
  virtual double durationSec() const = 0;         // natural length (a trace's length; generators: configured)
  virtual std::string describe() const = 0;
  // Last time the stream has data for. Generators are defined for any t (+inf); a trace ends at
  // its last row, and asking for a later time is the caller's error (check before a run).
  virtual double validUntilSec() const { return std::numeric_limits<double>::infinity(); }
  // Times (s) where the motion starts, stops or jumps (saccade, stop of a pursuit, start of a
  // lean), ascending: where ghosting and recovery are measured. Empty for continuous motion.
  virtual std::vector<double> motionChangeTimes() const { return {}; }
  // Head speed |omega| in deg/s at t, from the stream's angular velocity (instantaneous, not a
  // difference of two frames' poses, which quantises small angles and lags by half a frame).
  double headSpeedDegPerSec(double tSec) const;
};

struct FixationParams {
  double durationSec = 10.0;
  double tremorAmplitudeDeg = 0.02;  // RMS of physiological tremor, per axis
  double tremorLowHz = 8.0;          // tremor energy band
  double tremorHighHz = 12.0;
  double driftDegPerSec = 0.1;       // slow random-walk drift
  double jumpsPerSec = 0.2;          // occasional small corrective jumps (Poisson-timed)
  double jumpAmplitudeDeg = 0.15;    // each jump is 0.5-1.5x this, random direction
  double jumpRampSec = 0.06;         // a small corrective head movement takes tens of ms
  double translationTremorMm = 0.2;  // RMS per axis, 0.5-4 Hz
};

struct TurnParams {
  double durationSec = 3.0;
  double peakSpeedDegPerSec = 20.0;  // pursuit: slow steady turn; fast turn: well above 25
  glm::vec3 axis{0.0f, 1.0f, 0.0f};  // yaw by default
  double rampSec = 0.3;              // smooth start and stop
};

std::unique_ptr<MotionStream> makeFixation(const FixationParams& p, uint64_t seed);
std::unique_ptr<MotionStream> makePursuit(const TurnParams& p, uint64_t seed);  // default 20 deg/s
std::unique_ptr<MotionStream> makeFastTurn(const TurnParams& p,
                                           uint64_t seed);  // default params -> 200 deg/s
// Concatenates streams; each segment starts from where the previous one ended.
std::unique_ptr<MotionStream> makeSequence(std::vector<std::unique_ptr<MotionStream>> parts);
// Trace file (CSV): header line then rows of
//   t_s,qw,qx,qy,qz[,wx,wy,wz][,px,py,pz]   or   t_s,wx,wy,wz  (angular velocity only, integrated)
// Columns are found by name; returns nullptr and fills *error on malformed files.
std::unique_ptr<MotionStream> loadTrace(const std::string& path, std::string* error);
// Named presets used by the emulator CLI and the harness (motionPresets() lists them), plus
// "trace:PATH". Every preset is seeded by seed. nullptr and *error for an unknown name.
std::unique_ptr<MotionStream> makePreset(const std::string& name, uint64_t seed, std::string* error);

struct MotionPreset {
  std::string name;         // what makePreset() takes
  std::string motionClass;  // grouping: "still", "saccade", "sway", "pursuit", "turn", "translation", "mixed"
  std::string summary;      // one line: what it is and its parameters
  bool inCorpus = true;     // false: kept for the default suite and the tools, covered by another preset
};
// Every preset, corpus ones first (the harness's --corpus iterates over those with inCorpus).
const std::vector<MotionPreset>& motionPresets();

}  // namespace steadyxr::imu
