// The filter's CPU-side geometry: pose checks, reprojection matrices, depth to 1/z, parallax.
#pragma once

#include <glm/mat4x4.hpp>

#include "pass_uniforms.h"
#include "steadyxr/core/frame.h"
#include "steadyxr/core/params.h"

namespace steadyxr::core::detail {

bool finitePose(const Pose& p);
bool finiteFov(const Fov& f);

// Maps a pixel (x, y, 1, 1/z) of the view at `from` to homogeneous pixel coordinates of the image
// seen from `to` (seed 003 Eq. 1 when `to` is an interpolated pose).
glm::mat4 reprojection(const Pose& from, const Fov& fromFov, VkExtent2D fromSize, const Pose& to,
                       const Fov& toFov, VkExtent2D toSize);

bool validDepth(const DepthRef& d);
DepthToInvZ depthToInvZ(const DepthRef& d);

// Squared spread (px^2) of where a point's image lies in `v`'s eye seen from `otherPose`, over the
// depths between the far plane (what a reprojection assumes without depth) and
// steadyNearestDepthM: focal length in px times |eye offset| times the spread of 1/z. The stereo
// pass's disparity without depth (otherPose: the other eye's).
float parallaxSpreadPx2(const Params& params, const ViewFrame& v, const Pose& otherPose, VkExtent2D eyeSize);

}  // namespace steadyxr::core::detail
