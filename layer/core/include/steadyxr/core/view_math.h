// CPU-side math shared by the filter core, the layer and the evaluation harness.
// Projection matrices map view space (OpenXR: -Z forward, +Y up) to Vulkan clip space
// (NDC x right, y down, depth in [0,1]).
#pragma once

#include "steadyxr/core/frame.h"

#include <glm/mat4x4.hpp>

namespace steadyxr::core {

// Asymmetric perspective projection from OpenXR-style fov angles. farZ may be +inf.
glm::mat4 projectionFromFov(const Fov& fov, float nearZ, float farZ);
// World-to-view matrix (inverse of the pose).
glm::mat4 viewFromPose(const Pose& pose);
// Pose interpolation: slerp of orientation, lerp of position; t = 0 gives a, t = 1 gives b.
Pose interpolatePose(const Pose& a, const Pose& b, float t);
// Angle between two orientations in degrees.
float angleBetweenDeg(const glm::quat& a, const glm::quat& b);

// Seed 003 Eq. 4: the global weight of the current colour from head angular speed (deg/s).
float globalWeightA(float headSpeedDegPerSec, float hMaxDegPerSec, float wMin);
// Seed 003 Eq. 5: the localised minimum weight for a pixel's temporal colour difference in [0,1].
float localisedWMin(float wMin, float wLowerBound, float colourDifference);
// Seed 003 Eq. 2: weights W(d_i) for n samples, summing to 1. d = 1 is the current pose (most
// recent), d = 0 the full inverse of the head motion; W is monotone: larger d, weight >= .
void sampleWeightsW(const float* d, uint32_t n, float* weightsOut);

}  // namespace steadyxr::core
