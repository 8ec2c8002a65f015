// The simulated headset's eyes: IPD, clip planes, per-eye fov, and the two eye cameras of a head
// pose (optionally with the layer's sub-pixel jitter).
#pragma once

#include "camera.h"

#include "steadyxr/core/frame.h"

#include <array>

#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace steadyxr::eval {

constexpr float kIpdM = 0.064f;
constexpr float kNearZ = 0.05f;
constexpr float kFarZ = 100.0f;

// Per-eye fov of a typical HMD: wider towards the temple than the nose (radians).
core::Fov eyeFov(int eye);

// Pixels per degree at the centre of a view `width` pixels wide with this fov: the horizontal
// focal length in pixels, width / (tan(right) - tan(left)), times pi/180.
double centrePixelsPerDegree(const core::Fov& fov, int width);

// --ppd: how much a headset at `pixelsPerDegree` (at the centre, horizontally) narrows eyeFov at
// this width: the factor on every tangent of the fov. 1 when pixelsPerDegree <= 0 (off).
double ppdTangentScale(double pixelsPerDegree, int width);

// The fov with every tangent times `tangentScale` (the asymmetric shape and the pixel aspect kept), its
// horizontal tangents then moved by `centreTangentX` (a crop of the view around that direction; --cant).
core::Fov scaleFovTangents(const core::Fov& fov, double tangentScale, double centreTangentX = 0.0);

struct HeadPose {
  glm::quat orientation{1, 0, 0, 0};
  glm::vec3 position{0.0f};
};

// --ppd for a scene in metres: the world map that stretches depth along `start`'s view direction
// by 1/tangentScale about its eye centre and keeps the two lateral axes. A point at view-frame
// (x, y, z) goes to (x, y, z / s); its tangents x/z, y/z shrink by s while the narrowed fov's
// focal length in pixels grows by 1/s, so from `start` it lands on the pixel it had without
// --ppd, in both eyes (they sit on the lateral axis). It is the image viewer's rule (scene.cpp,
// picturePlane: 1.5 m / s, size kept) for any geometry. A uniform scale would not do: it keeps
// angles, so the narrowed fov would show the scene 1/s times larger in pixels.
glm::mat4 ppdDepthStretch(const HeadPose& start, double tangentScale);

// The headset's optics as the eval models them: --ppd and --cant.
struct EyeRig {
  // > 0: the fov's tangents and kNearZ times ppdTangentScale (--ppd); 0: eyeFov as it is.
  double pixelsPerDegree = 0.0;
  // Each eye's view yawed outwards by this many degrees (--cant), as a headset with canted displays
  // reports its views (the Pimax 5k+'s native mode: 10 degrees; parallel views: 0). With --ppd each eye's
  // crop is the part of its canted view around the head's straight-ahead direction, which both eyes see,
  // where parallel eyes' crops are at their centres: an off-axis frustum, as a region of the headset's view.
  double cantDeg = 0.0;
};

// jitterPx: the layer's sub-pixel jitter (core::jitterFov), zero for an unjittered render.
std::array<EyeCamera, 2> eyeCameras(const HeadPose& head, int w, int h, const EyeRig& rig,
                                    glm::vec2 jitterPx = glm::vec2(0.0f));

}  // namespace steadyxr::eval
