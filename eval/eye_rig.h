// The simulated headset's eyes: IPD, clip planes, per-eye fov, and the two eye cameras of a head
// pose (optionally with the layer's sub-pixel jitter).
#pragma once

#include "camera.h"

#include "steadyxr/core/frame.h"

#include <array>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace steadyxr::eval {

constexpr float kIpdM = 0.064f;
constexpr float kNearZ = 0.05f;
constexpr float kFarZ = 100.0f;

// Per-eye fov of a typical HMD: wider towards the temple than the nose (radians).
core::Fov eyeFov(int eye);

struct HeadPose {
  glm::quat orientation{1, 0, 0, 0};
  glm::vec3 position{0.0f};
};

// jitterPx: the layer's sub-pixel jitter (core::jitterFov), zero for an unjittered render.
std::array<EyeCamera, 2> eyeCameras(const HeadPose& head, int w, int h, glm::vec2 jitterPx = glm::vec2(0.0f));

}  // namespace steadyxr::eval
