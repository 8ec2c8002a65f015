// The simulated headset's eye fovs and eye cameras.
#include "eye_rig.h"

#include "steadyxr/core/jitter.h"

#include <cmath>
#include <numbers>

#include <glm/gtc/matrix_transform.hpp>

namespace steadyxr::eval {

// Per-eye fov of a typical HMD: wider towards the temple than the nose (radians).
core::Fov eyeFov(int eye) {
  core::Fov f;
  f.angleUp = 0.80f;
  f.angleDown = -0.84f;
  f.angleLeft = eye == 0 ? -0.82f : -0.73f;
  f.angleRight = eye == 0 ? 0.73f : 0.82f;
  return f;
}

double centrePixelsPerDegree(const core::Fov& fov, int width) {
  const double focalPx = width / (std::tan(double(fov.angleRight)) - std::tan(double(fov.angleLeft)));
  return focalPx * std::numbers::pi / 180.0;
}

double ppdTangentScale(double pixelsPerDegree, int width) {
  if (pixelsPerDegree <= 0.0) return 1.0;
  // Both eyes' fovs are mirror images: the same horizontal tangent span, the same factor.
  return centrePixelsPerDegree(eyeFov(0), width) / pixelsPerDegree;
}

core::Fov scaleFovTangents(const core::Fov& fov, double tangentScale, double centreTangentX) {
  auto scaled = [tangentScale](float angle, double centre = 0.0) {
    return float(std::atan(centre + tangentScale * std::tan(double(angle))));
  };
  core::Fov out;
  out.angleLeft = scaled(fov.angleLeft, centreTangentX);
  out.angleRight = scaled(fov.angleRight, centreTangentX);
  out.angleUp = scaled(fov.angleUp);
  out.angleDown = scaled(fov.angleDown);
  return out;
}

glm::mat4 ppdDepthStretch(const HeadPose& start, double tangentScale) {
  const glm::mat4 toView =
      glm::mat4_cast(glm::inverse(start.orientation)) * glm::translate(glm::mat4(1.0f), -start.position);
  const glm::mat4 stretch = glm::scale(glm::mat4(1.0f), glm::vec3(1.0f, 1.0f, float(1.0 / tangentScale)));
  return glm::inverse(toView) * stretch * toView;
}

std::array<EyeCamera, 2> eyeCameras(const HeadPose& head, int w, int h, const EyeRig& rig,
                                    glm::vec2 jitterPx) {
  std::array<EyeCamera, 2> cams;
  const double tangentScale = ppdTangentScale(rig.pixelsPerDegree, w);
  for (int eye = 0; eye < 2; ++eye) {
    core::Pose p;
    // Outwards: the left eye turns left (a positive yaw about +Y turns -Z towards -X), the right eye right.
    const float cantRad = float(rig.cantDeg * std::numbers::pi / 180.0) * (eye == 0 ? 1.0f : -1.0f);
    p.orientation = rig.cantDeg == 0.0
                        ? head.orientation
                        : head.orientation * glm::angleAxis(cantRad, glm::vec3(0.0f, 1.0f, 0.0f));
    p.position = head.position + head.orientation * glm::vec3(eye == 0 ? -kIpdM / 2 : kIpdM / 2, 0.0f, 0.0f);
    // Off (scale 1): eyeFov untouched, so every result without --ppd stays bit-identical. A canted eye's crop
    // is centred on the head's straight ahead, which lies at tan(cant) towards the nose in the eye's view.
    const core::Fov eyeFovHere = tangentScale == 1.0
                                     ? eyeFov(eye)
                                     : scaleFovTangents(eyeFov(eye), tangentScale, std::tan(double(cantRad)));
    const core::Fov fov = core::jitterFov(eyeFovHere, jitterPx.x, jitterPx.y, uint32_t(w), uint32_t(h));
    // The near plane moves out with the picture (scene.cpp, picturePlane): the depth buffer holds
    // the values it holds without --ppd, and the ground truth's background quad at raster depth
    // 0.999 (renderer.cpp) stays behind the picture (with a 0.05 m near plane it would be in front).
    cams[eye] = makeEyeCamera(p, fov, w, h, float(kNearZ / tangentScale), kFarZ);
  }
  return cams;
}

}  // namespace steadyxr::eval
