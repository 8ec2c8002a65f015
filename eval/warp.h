// The display stage: what happens after the layer when the display outruns the app.
// (a) rotational timewarp of the latest frame, as OpenXR runtimes do;
// (b) seed 004's forward depth-image warping: every pixel becomes a 3D point, is moved by its
//     per-pixel motion (scaled by the extrapolation fraction) and splatted into the new view.
#pragma once

#include "camera.h"
#include "image.h"

#include <functional>

#include <glm/vec3.hpp>

namespace steadyxr::eval {

// Pixels that map outside the source image are black.
Image rotationalTimewarp(const Image& source, const EyeCamera& sourceCam, const EyeCamera& displayCam);

// World-space motion of a surface point over one app frame (seed 004's V = P_n - P_{n-1}).
using MotionField = std::function<glm::vec3(const glm::vec3& worldPoint)>;

// Forward warp with a z-buffer; single-pixel holes are filled from the nearest neighbour,
// larger holes stay black (they count as error pixels, as in seed 004).
Image forwardDepthWarp(const Image& source, const DepthMap& depth, const EyeCamera& sourceCam,
                       const EyeCamera& displayCam, const MotionField& motion, float fraction);

}  // namespace steadyxr::eval
