// The cases a run covers (the default suite, a chosen scenes x motions grid, or the corpus) and the
// textures they need.
#pragma once

#include "scenario.h"
#include "scene.h"
#include "suite.h"

#include <string>
#include <vector>

namespace steadyxr::eval {

// The scenarios of options `o`; empty with *error set on an unknown scene.
std::vector<Scenario> buildScenarios(const Options& o, std::string* error);

// Every texture any of `scenarios` needs, loaded once (index 0 = white). False with *error when a
// scenario's picture does not load (loadPicture); the scenes' own extra pictures fall back.
bool gatherTextures(const std::vector<Scenario>& scenarios, const Options& o, TextureSet* textures,
                    std::string* error);

}  // namespace steadyxr::eval
