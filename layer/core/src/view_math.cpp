#include "steadyxr/core/view_math.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace steadyxr::core {

glm::mat4 projectionFromFov(const Fov& fov, float nearZ, float farZ) {
  const float l = std::tan(fov.angleLeft), r = std::tan(fov.angleRight);
  const float u = std::tan(fov.angleUp), d = std::tan(fov.angleDown);
  const float w = r - l, h = u - d;  // Vulkan NDC: y down, so up maps to -1
  glm::mat4 m(0.0f);                 // column-major: m[col][row]
  m[0][0] = 2.0f / w;
  m[2][0] = (r + l) / w;
  m[1][1] = -2.0f / h;
  m[2][1] = -(u + d) / h;
  m[2][3] = -1.0f;
  if (std::isinf(farZ)) {
    m[2][2] = -1.0f;
    m[3][2] = -nearZ;
  } else {
    m[2][2] = farZ / (nearZ - farZ);
    m[3][2] = nearZ * farZ / (nearZ - farZ);
  }
  return m;
}

glm::mat4 viewFromPose(const Pose& pose) {
  const glm::mat4 rot = glm::mat4_cast(glm::conjugate(glm::normalize(pose.orientation)));
  return rot * glm::translate(glm::mat4(1.0f), -pose.position);
}

Pose interpolatePose(const Pose& a, const Pose& b, float t) {
  Pose p;
  p.orientation = glm::slerp(glm::normalize(a.orientation), glm::normalize(b.orientation), t);
  p.position = a.position + (b.position - a.position) * t;
  return p;
}

float angleBetweenDeg(const glm::quat& a, const glm::quat& b) {
  // 2 atan2(|v|, |w|) of the relative rotation, in double: exact for small angles. acos of a
  // float dot product returned 0 below ~0.04 deg and moved in ~1.2 deg/s steps at 90 Hz (the
  // float spacing of the dot product near 1, 6e-8, is a ~0.04 deg angle).
  const glm::dquat r = glm::conjugate(glm::normalize(glm::dquat(a))) * glm::normalize(glm::dquat(b));
  const double v = std::sqrt(r.x * r.x + r.y * r.y + r.z * r.z);
  return static_cast<float>(glm::degrees(2.0 * std::atan2(v, std::abs(r.w))));
}

float globalWeightA(float h, float hMax, float wMin) {
  if (!(h <= hMax)) return 1.0f;  // also for NaN: use the current frame only
  const float pi = 3.14159265358979f;
  const float s = -0.5f * (std::cos(pi * std::max(h, 0.0f) / hMax) - 1.0f);
  return (1.0f - wMin) * s * s + wMin;
}

float localisedWMin(float wMin, float wLowerBound, float colourDifference) {
  return wMin - (wMin - wLowerBound) * std::clamp(colourDifference, 0.0f, 1.0f);
}

void sampleWeightsW(const float* d, uint32_t n, float* weightsOut) {
  // W(d) proportional to 1 + d: positive, monotone in d (more recent = larger), sums to 1.
  float sum = 0.0f;
  for (uint32_t i = 0; i < n; ++i) sum += 1.0f + std::clamp(d[i], 0.0f, 1.0f);
  for (uint32_t i = 0; i < n; ++i) weightsOut[i] = (1.0f + std::clamp(d[i], 0.0f, 1.0f)) / sum;
}

}  // namespace steadyxr::core
