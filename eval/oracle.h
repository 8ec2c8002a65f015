// The oracle (issue 13): an upper bound for history-based filters on static scenes, computed by
// the harness on the CPU from the rendered frames. Every rendered sample of the last kWindow
// frames is carried exactly (its frame's true depth and camera pose) to where it lies in the
// current output grid, and each output pixel averages, with equal weights 1/N, the samples that
// fall inside its area: no resampling blur, no clipping, no history weight, no lag. Where the
// head translated, samples the current depth does not confirm (occluded now) are dropped; under
// pure rotation visibility cannot change and none is. Not a shipped method; it shows how much
// headroom any method has left with the same samples.
#pragma once

#include "camera.h"
#include "image.h"

#include <array>
#include <deque>

namespace steadyxr::eval {

class Oracle {
 public:
  // 16 frames: two periods of the layer's 8-frame Halton jitter, so a jittered run gets every
  // sub-pixel offset twice; about what a TAA with alpha 0.1 remembers.
  static constexpr size_t kWindow = 16;

  explicit Oracle(bool linearLight) : linear_(linearLight) {}
  void reset();
  // Adds eye `eye`'s frame (rendered with `renderCam`, possibly jittered) and returns the estimate
  // on `outCam`'s grid, whose true depth is `outDepth`. Images are display-encoded; with
  // linearLight the average is taken in linear light.
  Image step(int eye, const Image& rendered, const DepthMap& renderedDepth, const EyeCamera& renderCam,
             const DepthMap& outDepth, const EyeCamera& outCam);

 private:
  struct Frame {
    Image color;  // linear light when linear_
    DepthMap depth;
    EyeCamera cam;
  };
  bool linear_;
  std::array<std::deque<Frame>, 2> frames_;
};

}  // namespace steadyxr::eval
