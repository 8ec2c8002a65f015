// The simulated headset's eye fovs and eye cameras.
#include "eye_rig.h"

#include "steadyxr/core/jitter.h"

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

// jitterPx: the layer's sub-pixel jitter (core::jitterFov), zero for an unjittered render.
std::array<EyeCamera, 2> eyeCameras(const HeadPose& head, int w, int h, glm::vec2 jitterPx) {
  std::array<EyeCamera, 2> cams;
  for (int eye = 0; eye < 2; ++eye) {
    core::Pose p;
    p.orientation = head.orientation;
    p.position = head.position + head.orientation * glm::vec3(eye == 0 ? -kIpdM / 2 : kIpdM / 2, 0.0f, 0.0f);
    const core::Fov fov = core::jitterFov(eyeFov(eye), jitterPx.x, jitterPx.y, uint32_t(w), uint32_t(h));
    cams[eye] = makeEyeCamera(p, fov, w, h, kNearZ, kFarZ);
  }
  return cams;
}

}  // namespace steadyxr::eval
