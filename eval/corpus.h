// --corpus: every head-motion preset over a picture set and the scene set in one run, summarised
// in one table per motion class and picture class (docs/evaluation-corpus.md).
#pragma once

#include "results.h"
#include "scenario.h"

#include <iosfwd>
#include <string>
#include <vector>

namespace steadyxr::eval {

struct Options;

// The motion presets the corpus runs (imu presets), the pictures and the scenes.
const std::vector<std::string>& corpusMotions();
const std::vector<std::string>& corpusPictures();
const std::vector<std::string>& corpusMethods();
// The preset's class for the table (imu::MotionPreset::motionClass: still, saccade, sway, pursuit,
// turn, translation, mixed).
std::string motionClassOf(const std::string& preset);
// Whether a preset moves the head's position by more than 1 cm (then every case runs twice: with
// the app's depth given to the filter and without; most apps submit none).
bool presetTranslates(const std::string& preset, uint64_t seed);

// Where a preset's run starts: the window of windowSec (the run's frames' span) that holds the most
// of its motion changes, each with 0.5 s of history before it (0 for presets without changes).
double corpusStartSec(const std::string& preset, uint64_t seed, double windowSec);
std::vector<Scenario> corpusScenarios(const Options& o);
// Per (motion class, picture class): mean RMSE relative to none's per method, and the default's
// temporal error, worst frame and recovery. Also written to corpus.csv.
void printCorpusTable(const std::vector<ResultRow>& rows, std::ostream& out);
void writeCorpusCsv(const std::string& path, const std::vector<ResultRow>& rows);

}  // namespace steadyxr::eval
