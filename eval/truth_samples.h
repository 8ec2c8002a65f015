// Where the ground truth samples a pixel: N x N sub-renders, each shifted by one offset.
#pragma once

#include <glm/vec2.hpp>

namespace steadyxr::eval {

// Offset (in pixels, within [-0.5, 0.5)) of sub-render (sx, sy) of the truth's gridSize x gridSize.
// N-rooks on the N x N strata (Chiu, Shirley and Wang's multi-jittered pattern, unshuffled): each
// N x N stratum holds one sample, and so does each of the N^2 columns and N^2 rows of the pixel. An
// axis-aligned edge (a picture's border, 1-px lines, text) is then covered in steps of 1/N^2, not a
// regular grid's 1/N, and the truth follows a sub-pixel motion of the edge in steps that small: with
// 4 x 4 a regular grid's truth stood still under tremor while the edge moved (round 19).
inline glm::vec2 truthSampleOffset(int sx, int sy, int gridSize) {
  const float cells = float(gridSize * gridSize);
  return {(float(sx * gridSize + sy) + 0.5f) / cells - 0.5f,
          (float(sy * gridSize + sx) + 0.5f) / cells - 0.5f};
}

}  // namespace steadyxr::eval
