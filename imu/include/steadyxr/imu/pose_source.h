// The interface the OpenXR layer's `imu` pose source and the evaluation harness use:
// time (ns, CLOCK_MONOTONIC unless a source says otherwise) -> head orientation and speed.
#pragma once

#include <cstdint>
#include <optional>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

namespace steadyxr::imu {

struct HeadState {
  int64_t timeNs = 0;
  glm::quat orientation{1.0f, 0.0f, 0.0f, 0.0f};  // head-to-world, OpenXR axes (+Y up, -Z forward)
  glm::vec3 angularVelocityRadPerSec{0.0f};       // in the head frame
  float headSpeedDegPerSec = 0.0f;                // smoothed |angular velocity|, what seed 003's A(h) takes
  bool predicted = false;                         // true when timeNs lies beyond the newest sample
};

class PoseSource {
 public:
  virtual ~PoseSource() = default;
  // Interpolates inside the stored history and predicts a short way beyond it. Thread-safe:
  // callable from the render thread while a reader thread writes. nullopt when there is no data
  // yet, or when timeNs is too far from the stored samples to answer honestly.
  virtual std::optional<HeadState> stateAt(int64_t timeNs) const = 0;
};

}  // namespace steadyxr::imu
