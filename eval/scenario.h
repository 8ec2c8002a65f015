// One case of a run: a scene, a head motion (preset or trace), a picture, and how it is given to
// the filter.
#pragma once

#include <string>

namespace steadyxr::eval {

struct Scenario {
  std::string label;
  std::string scene;
  std::string motion;  // preset name or trace path
  bool trace = false;
  std::string picture;
  std::string motionClass, pictureClass;  // corpus grouping
  bool depthGiven = true;  // the app submits depth (XR_KHR_composition_layer_depth) to the filter
  bool sweeps = true;      // run the parameter-sweep variants here
  double leadSec = 0.0;    // frames start this long before the stream (held at its t = 0 pose)
  double startSec = -1.0;  // where in the stream the run starts; < 0: Options::startSec
};

}  // namespace steadyxr::eval
