#include "camera.h"

#include "steadyxr/core/view_math.h"

#include <glm/glm.hpp>

namespace steadyxr::eval {

EyeCamera makeEyeCamera(const core::Pose& pose, const core::Fov& fov, int width, int height, float nearZ,
                        float farZ) {
  EyeCamera cam;
  cam.pose = pose;
  cam.fov = fov;
  cam.width = width;
  cam.height = height;
  cam.nearZ = nearZ;
  cam.farZ = farZ;
  cam.view = core::viewFromPose(pose);
  cam.proj = core::projectionFromFov(fov, nearZ, farZ);
  cam.viewProj = cam.proj * cam.view;
  cam.invViewProj = glm::inverse(cam.viewProj);
  return cam;
}

glm::vec3 unproject(const EyeCamera& cam, float fx, float fy, float depth) {
  const glm::vec4 ndc(2.0f * fx / cam.width - 1.0f, 2.0f * fy / cam.height - 1.0f, depth, 1.0f);
  const glm::vec4 world = cam.invViewProj * ndc;
  return glm::vec3(world) / world.w;
}

bool project(const EyeCamera& cam, const glm::vec3& world, glm::vec2* pixel, float* depth) {
  const glm::vec4 clip = cam.viewProj * glm::vec4(world, 1.0f);
  if (clip.w <= 1e-6f) return false;
  const glm::vec3 ndc = glm::vec3(clip) / clip.w;
  *pixel = glm::vec2((ndc.x + 1.0f) * 0.5f * cam.width, (ndc.y + 1.0f) * 0.5f * cam.height);
  if (depth) *depth = ndc.z;
  return true;
}

glm::vec3 pixelDirection(const EyeCamera& cam, float fx, float fy) {
  const glm::vec4 ndc(2.0f * fx / cam.width - 1.0f, 2.0f * fy / cam.height - 1.0f, 0.5f, 1.0f);
  const glm::vec4 v = glm::inverse(cam.proj) * ndc;
  const glm::vec3 viewDir = glm::normalize(glm::vec3(v) / v.w);
  return cam.pose.orientation * viewDir;
}

bool projectDirection(const EyeCamera& cam, const glm::vec3& worldDir, glm::vec2* pixel) {
  const glm::vec3 viewDir = glm::inverse(cam.pose.orientation) * worldDir;
  const glm::vec4 clip = cam.proj * glm::vec4(viewDir, 1.0f);
  if (clip.w <= 1e-6f) return false;
  *pixel =
      glm::vec2((clip.x / clip.w + 1.0f) * 0.5f * cam.width, (clip.y / clip.w + 1.0f) * 0.5f * cam.height);
  return true;
}

}  // namespace steadyxr::eval
