// The evaluation suite: scenarios (scene x head motion [x picture]) x methods, per frame:
// render at the frame's head pose (both eyes) -> filter core -> display stage -> metrics.
#pragma once

#include "locomotion.h"
#include "scene.h"

#include "steadyxr/core/vulkan_context.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace steadyxr::eval {

struct Options {
  std::vector<std::string> scenes;   // empty: the default suite's scenario list
  std::vector<std::string> motions;  // presets: fixation, pursuit, fastturn, sequence
  std::vector<std::string> traces;   // trace CSV files (imu::loadTrace)
  std::vector<std::string> images;   // pictures for the image-viewer scenes (paths or skimage names)
  std::vector<std::string> methods;  // empty: all (see --help)
  int width = 256;
  int height = 256;
  int frames = 40;
  uint64_t seed = 1;
  std::string outDir = "out";
  std::string picturesDir = kDefaultPicturesDir;  // where built-in picture names are looked up
  double appHz = 30.0;
  double displayHz = 90.0;
  double startSec = 0.0;
  int gtGrid = 8;               // ground truth: gtGrid^2 N-rooks samples per pixel (truth_samples.h)
  int warpSteps = 6;            // seed 004 study: extrapolate up to this many display frames
  float errorThreshold = 0.1f;  // seed 004 error-pixel threshold (any channel, [0, 1] scale)
  float noise = 0.0f;   // > 0: per-frame noise of this amplitude on every scene (noisy variant of any scene)
  bool unorm = false;   // eye images and textures UNORM (encoded values) instead of sRGB (linear light)
  bool mipmaps = true;  // trilinear mipmapped textures; false: the base level only (worst case)
  bool corpus = false;  // every motion preset x the corpus pictures and scenes (corpus.h)
  std::string animate;  // case label to write an animated comparison of ("" = none; corpus: none)
  int writeFramesEvery = 0;  // > 0: every Nth frame's left-eye truth and outputs as PNG (frames/CASE/)
  bool sweeps = true;
  bool progress = true;
  bool validation = false;
  bool quick = false;
  // > 0: a headset's pixels per degree at the view's centre (eye_rig.h, ppdTangentScale); 0: eyeFov.
  double ppd = 0.0;
  // > 0: canted displays, each eye's view yawed outwards by this many degrees (eye_rig.h, EyeRig).
  double cantDeg = 0.0;
  EyeRig eyeRig() const { return {ppd, cantDeg}; }
  // The app's samples per pixel: 2 or 4 renders its eye images with MSAA, resolved, as most VR apps do;
  // every method then takes the resolved image as the app's (`none` is it). 1: one sample.
  int appMsaa = 1;
  // The app's own rig motion on top of the head's, which the layer is not told (locomotion.h).
  Locomotion locomotion;
  // > 0: the share of app periods the app misses (frame_clock.h): a missed frame's pose step is two periods.
  double dropFrames = 0.0;
  // Not empty: the dynamic-resolution study (render_size_study.h) in place of the suite, the app's render
  // size each frame the next of these fractions of width x height.
  std::vector<double> renderSizes;
};

// Returns the process exit code (0 on success).
int runSuite(const Options& options);

// The harness's own Vulkan context (validation with --validation); null with *error set.
std::unique_ptr<core::VulkanContext> createEvalContext(const Options& o, std::string* error);

}  // namespace steadyxr::eval
