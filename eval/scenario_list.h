// The cases a run covers (the default suite, a chosen scenes x motions grid, or the corpus) and the
// textures they need.
#pragma once

#include "scenario.h"
#include "scene.h"
#include "suite.h"

#include "steadyxr/imu/motion.h"

#include <memory>
#include <string>
#include <vector>

namespace steadyxr::eval {

// The scenarios of options `o`; empty with *error set on an unknown scene.
std::vector<Scenario> buildScenarios(const Options& o, std::string* error);

// Every texture any of `scenarios` needs, loaded once (index 0 = white). False with *error when a
// scenario's picture does not load (loadPicture); the scenes' own extra pictures fall back.
bool gatherTextures(const std::vector<Scenario>& scenarios, const Options& o, TextureSet* textures,
                    std::string* error);

// A case's head motion, and where its frames start on the stream's clock.
struct CaseMotion {
  std::unique_ptr<imu::MotionStream> stream;
  double startSec = 0.0;       // where the run starts in the stream (the case's, else Options::startSec)
  double firstFrameSec = 0.0;  // the first frame: the case's lead before that (held at the t = 0 pose)
};
// False with the message to print in *error (an unknown preset, a trace that does not load).
bool loadMotion(const Scenario& sc, const Options& o, CaseMotion* motion, std::string* error);

// Both, as a run starts (the suite, the render-size study): false with the message to print in *error.
bool loadCases(const Options& o, std::vector<Scenario>* scenarios, TextureSet* textures, std::string* error);

}  // namespace steadyxr::eval
