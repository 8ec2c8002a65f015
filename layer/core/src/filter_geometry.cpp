// The filter's CPU-side geometry: pose checks, reprojection matrices, depth to 1/z, parallax.
#include "filter_geometry.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "filter_formats.h"
#include "steadyxr/core/view_math.h"

namespace steadyxr::core::detail {

namespace {

// (px, py, 1, 1/z) in a view's rect pixels -> homogeneous view-space point.
glm::mat4 pixelToView(const Fov& f, VkExtent2D size) {
  const float l = std::tan(f.angleLeft), r = std::tan(f.angleRight);
  const float u = std::tan(f.angleUp), d = std::tan(f.angleDown);
  glm::mat4 m(0.0f);  // m[col][row]
  m[0][0] = (r - l) / static_cast<float>(size.width);
  m[2][0] = l;
  m[1][1] = -(u - d) / static_cast<float>(size.height);
  m[2][1] = u;
  m[2][2] = -1.0f;
  m[3][3] = 1.0f;
  return m;
}

// View-space homogeneous point -> (qx*s, qy*s, s, s/z) with q in the rect's pixels, s = distance.
glm::mat4 viewToPixel(const Fov& f, VkExtent2D size) {
  const float l = std::tan(f.angleLeft), r = std::tan(f.angleRight);
  const float u = std::tan(f.angleUp), d = std::tan(f.angleDown);
  const float sx = static_cast<float>(size.width) / (r - l);
  const float sy = static_cast<float>(size.height) / (u - d);
  glm::mat4 m(0.0f);
  m[0][0] = sx;
  m[2][0] = sx * l;
  m[1][1] = -sy;
  m[2][1] = -sy * u;
  m[2][2] = -1.0f;
  m[3][3] = 1.0f;
  return m;
}

glm::mat4 poseMatrix(const Pose& p) {
  return glm::translate(glm::mat4(1.0f), p.position) * glm::mat4_cast(glm::normalize(p.orientation));
}

}  // namespace

bool finitePose(const Pose& p) {
  return std::isfinite(p.orientation.w) && std::isfinite(p.orientation.x) && std::isfinite(p.orientation.y) &&
         std::isfinite(p.orientation.z) && std::isfinite(p.position.x) && std::isfinite(p.position.y) &&
         std::isfinite(p.position.z) && glm::dot(p.orientation, p.orientation) > 1e-12f;
}
bool finiteFov(const Fov& f) {
  return std::isfinite(f.angleLeft) && std::isfinite(f.angleRight) && std::isfinite(f.angleUp) &&
         std::isfinite(f.angleDown) && f.angleRight > f.angleLeft && f.angleUp > f.angleDown &&
         std::abs(f.angleLeft) < 1.57f && std::abs(f.angleRight) < 1.57f && std::abs(f.angleUp) < 1.57f &&
         std::abs(f.angleDown) < 1.57f;
}

glm::mat4 reprojection(const Pose& from, const Fov& fromFov, VkExtent2D fromSize, const Pose& to,
                       const Fov& toFov, VkExtent2D toSize) {
  return viewToPixel(toFov, toSize) * viewFromPose(to) * poseMatrix(from) * pixelToView(fromFov, fromSize);
}

bool validDepth(const DepthRef& d) {
  return isDepthFormat(d.image.format) && std::isfinite(d.nearZ) && d.nearZ > 0.0f && d.farZ > 0.0f &&
         !std::isnan(d.farZ) && d.nearZ != d.farZ && std::isfinite(d.minDepth) && std::isfinite(d.maxDepth);
}

DepthToInvZ depthToInvZ(const DepthRef& d) {
  // 1/z is linear in normalised depth: 1/z = 1/nearZ + n * (1/farZ - 1/nearZ); farZ may be +inf.
  const float invNear = 1.0f / d.nearZ;
  const float invFar = std::isinf(d.farZ) ? 0.0f : 1.0f / d.farZ;
  const float range = d.maxDepth - d.minDepth;
  return {invNear, invFar - invNear, d.minDepth, range != 0.0f ? 1.0f / range : 1.0f};
}

float parallaxSpreadPx2(const Params& params, const ViewFrame& v, const Pose& otherPose, VkExtent2D eyeSize) {
  const float nearest = params.steadyNearestDepthM;
  if (!std::isfinite(nearest) || !(nearest > 0.0f)) return 0.0f;
  const float invFar = std::isinf(params.stereoFarDistanceM) ? 0.0f : 1.0f / params.stereoFarDistanceM;
  const float spreadInvZ = std::max(1.0f / nearest - invFar, 0.0f);
  const float focalPx =
      static_cast<float>(eyeSize.width) / (std::tan(v.fov.angleRight) - std::tan(v.fov.angleLeft));
  const float e = focalPx * glm::length(v.pose.position - otherPose.position) * spreadInvZ;
  return std::isfinite(e) ? std::min(e * e, 1e6f) : 1e6f;
}

}  // namespace steadyxr::core::detail
