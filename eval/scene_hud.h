// Head-locked content drawn into the eye images (scene `hud`): a reticle and a text panel that an
// app places at a fixed pose in head space and renders into its projection layer, in front of the
// image viewer's world-locked picture. To a layer that reprojects by the head's motion it is an
// object moving on screen by exactly minus that motion (issue 14, round 7).
#pragma once

#include "camera.h"
#include "eye_rig.h"
#include "image.h"
#include "renderer.h"

#include <array>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>

namespace steadyxr::eval {

struct TextureSet;

// The head-space placement's distance (m) without --ppd: in front of the picture (1.5 m) and at the
// 1-2 m where apps put a HUD (the far end of Oculus' comfortable 0.75-3.5 m range sits beyond it).
inline constexpr float kHudDistanceM = 1.0f;

// Head space -> world for a render pose (what an app multiplies a head-locked model by).
glm::mat4 headToWorld(const HeadPose& head);

// The HUD's quads in head space (model maps the unit quad into head space: x right, y up, -z ahead).
// Under --ppd (fovTangentScale < 1) it is 1/fovTangentScale times further with its size kept, as
// the image viewer's picture (scene.cpp, picturePlane), so it keeps its pixels. Sizes are set for
// the corpus's eye width of 96 px (0.0205 m per px at 1 m: eyeFov's tangent span 1.967 / 96):
// reticle lines 1.5 px wide, arms 12 px; the panel about 7 % of the image.
std::vector<DrawQuad> hudOverlay(const TextureSet& textures, double fovTangentScale);

// Pixels covered by head-locked content in one eye's render: view-space distance nearer than
// `splitDistanceM` (between the HUD and the picture), dilated by one pixel so that the overlay's
// partly covered edge pixels count. Row-major, width x height.
// dilate = false: the near pixels alone (the overlay's core; the border is the difference).
std::vector<uint8_t> overlayMask(const DepthMap& depth, const EyeCamera& cam, float splitDistanceM,
                                 bool dilate = true);

// RMSE of a against b over the masked pixels (all three channels); -1 when the mask is empty.
double maskedRmse(const Image& a, const Image& b, const std::vector<uint8_t>& mask);
// The same over both eyes pooled (the root of the mean squared error over their masked pixels); -1 when
// both masks are empty. pixels (optional) gets the masked pixels' count, both eyes.
double pooledMaskedRmse(const std::array<Image, 2>& a, const std::array<Image, 2>& b,
                        const std::array<std::vector<uint8_t>, 2>& mask, double* pixels);

// Per eye: the overlay and its one-pixel ring (`all`, overlayMask dilated), the overlay's own pixels
// (`core`) and the ring of world pixels around them (`border` = all minus core).
struct OverlayMasks {
  std::array<std::vector<uint8_t>, 2> all, core, border;
};
// fovTangentScale: --ppd's (the HUD and the picture both move 1/s further, so does the split).
OverlayMasks overlayMasks(const std::array<const DepthMap*, 2>& depth, const std::array<EyeCamera, 2>& cams,
                          double fovTangentScale);

// overlay.csv (suite.cpp): after scenario, method and frame, the RMSE of both eyes pooled (the root
// of the mean squared error over their masked pixels) on `all`, its pixel count, on `core`, `border`.
inline constexpr const char* kOverlayCsvHeader =
    "scenario,method,frame,rmse_overlay,overlay_pixels,rmse_core,rmse_border";
std::string overlayCsvRow(const std::array<Image, 2>& out, const std::array<Image, 2>& truth,
                          const OverlayMasks& masks);

}  // namespace steadyxr::eval
