// The sub-pixel camera jitter the layer injects with `jitter = 1` (seed 001 §4.4: Halton(2,3)),
// in one place so that the layer and the evaluation harness render with the same offsets.
#pragma once

#include "steadyxr/core/frame.h"
#include "steadyxr/core/params.h"

#include <cstdint>

#include <glm/vec2.hpp>

namespace steadyxr::core {

// Halton low-discrepancy sequence value in [0, 1) (index >= 1).
float halton(uint32_t index, uint32_t base);

// The sequence repeats every 8 frames (as INSIDE's and Unreal's TAA: 8 offsets cover the pixel
// well enough while history, at alpha ~0.1, remembers about that many frames).
inline constexpr uint32_t kJitterPeriod = 8;

// The offset of the n-th jittered frame (n = 0, 1, ...) in pixels, in [-0.5, 0.5): Halton(2, 3)
// at index n % 8 + 1, centred. The layer's n-th xrLocateViews call gets this offset.
glm::vec2 haltonJitterPx(uint32_t frameIndex);

// The fov whose image grid is shifted by (dxPx, dyPx) pixels of a width x height image
// (x right, y down): what the app renders when the runtime hands it this fov. The point at pixel
// centre c of `fov`'s grid appears at c - (dxPx, dyPx) in the image rendered with the result,
// which is ViewFrame::jitterPx = (dxPx, dyPx).
Fov jitterFov(const Fov& fov, float dxPx, float dyPx, uint32_t width, uint32_t height);

// Whether the filter core un-jitters with this temporal method (only the history-blending ones
// do); with the others a jitter would only shake the image, so the layer injects none.
bool undoesJitter(TemporalMethod method);

}  // namespace steadyxr::core
