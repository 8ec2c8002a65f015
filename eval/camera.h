// One eye's camera in the harness: pose + fov -> the same matrices the filter core uses.
#pragma once

#include "steadyxr/core/frame.h"

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace steadyxr::eval {

struct EyeCamera {
  core::Pose pose;
  core::Fov fov;
  int width = 0;
  int height = 0;
  float nearZ = 0.05f;
  float farZ = 100.0f;
  glm::mat4 view{1.0f};
  glm::mat4 proj{1.0f};
  glm::mat4 viewProj{1.0f};
  glm::mat4 invViewProj{1.0f};
};

EyeCamera makeEyeCamera(const core::Pose& pose, const core::Fov& fov, int width, int height,
                        float nearZ = 0.05f, float farZ = 100.0f);

// World point of the pixel position (fx, fy) (pixel centres at +0.5) at raster depth `depth`.
glm::vec3 unproject(const EyeCamera& cam, float fx, float fy, float depth);
// Projects a world point; false when it lies behind the eye. Gives pixel coordinates and the
// raster depth in [0, 1].
bool project(const EyeCamera& cam, const glm::vec3& world, glm::vec2* pixel, float* depth);
// Unit view direction of a pixel in world space (ignores position: rotational warps).
glm::vec3 pixelDirection(const EyeCamera& cam, float fx, float fy);
// Pixel of a world-space direction seen from the eye's orientation only.
bool projectDirection(const EyeCamera& cam, const glm::vec3& worldDir, glm::vec2* pixel);

}  // namespace steadyxr::eval
