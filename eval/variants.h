// The methods a run compares ("variants"): a filter-core method name, optionally jittered
// ("+jitter"), MSAA baselines, the CPU oracle, and parameter sweeps ("<m>@key=value").
#pragma once

#include "steadyxr/core/filter.h"
#include "steadyxr/core/params.h"

#include <memory>
#include <string>
#include <vector>

namespace steadyxr::eval {

struct Variant {
  std::string name;
  core::Params params;
  int source = 1;  // 1 = the 1-sample render; 2 / 4 = MSAA
  bool sweep = false;
  bool jitter = false;       // rendered with the layer's Halton(2,3) jitter, un-jittered by the core
  bool oracle = false;       // the harness's CPU upper bound (oracle.h), no filter
  float noiseOracle = 0.0f;  // steady told the scene's true noise variance (noisevar=-1)
  bool autoHud = false;      // round 41's study: the profile hud from the frame after the detector decides
  std::unique_ptr<core::Filter> filter;
};

// Every method (each temporal one also +jitter, each also +stereo), "default", "oracle", and with
// `sweeps` the sweep points.
std::vector<std::string> defaultMethods(bool sweeps);
// "<method>[+jitter][@key=value]...": see --help.
bool parseVariant(const std::string& spec, Variant* v, std::string* error);

}  // namespace steadyxr::eval
