// The targets of issue 14 for the default method, checked by what a case is (its head speed, its
// motion changes), not by its name, over every case of a run (default suite or corpus).
#pragma once

#include "results.h"

#include <string>
#include <vector>

namespace steadyxr::eval {

// defaultTemporal: the temporal method inside "default" (the stereo target compares the default
// with that method alone).
std::vector<TargetCheck> checkTargets(const std::vector<ResultRow>& rows, const std::string& defaultTemporal);

}  // namespace steadyxr::eval
