#include "corpus.h"

#include "eye_rig.h"
#include "frame_clock.h"
#include "pictures.h"
#include "scene.h"
#include "suite.h"

#include "steadyxr/imu/motion.h"

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <ostream>

#include <glm/glm.hpp>

namespace steadyxr::eval {

namespace {

// History before a motion change: 15 frames at 30 Hz, about what a TAA with alpha 0.1 remembers.
constexpr double kPreRollSec = 0.5;

// The methods whose mean RMSE the corpus table shows, relative to none's.
const std::vector<std::string> kTableMethods = {
    "fxaa", "taa", "taa+jitter", "hmtaa", "hybrid", "default", "default+jitter", "oracle", "oracle+jitter"};

struct Group {
  int cases = 0;
  std::map<std::string, std::pair<double, int>> rmseRatio;  // method -> (sum of rmse/none, n)
  double tempErrSum = 0, mtcdSum = 0;
  int lowSpeedCases = 0;
  double worstRatio = 0;
  int worstRecovery = 0, defaultAboveNone = 0, defaultAboveTaa = 0;
};

std::map<std::pair<std::string, std::string>, Group> groups(const std::vector<ResultRow>& rows) {
  std::map<std::pair<std::string, std::string>, Group> out;
  std::map<std::string, const ResultRow*> none;
  for (const ResultRow& r : rows) {
    if (r.method == "none") none[r.scenario] = &r;
  }
  std::map<std::string, const ResultRow*> taa;
  for (const ResultRow& r : rows) {
    if (r.method == "taa") taa[r.scenario] = &r;
  }
  for (const ResultRow& r : rows) {
    const auto n = none.find(r.scenario);
    if (n == none.end() || n->second->rmse <= 0) continue;
    Group& g = out[{r.motionClass, r.pictureClass}];
    if (std::find(kTableMethods.begin(), kTableMethods.end(), r.method) != kTableMethods.end()) {
      auto& [sum, count] = g.rmseRatio[r.method];
      sum += r.rmse / n->second->rmse;
      ++count;
    }
    if (r.method == "default") {
      ++g.cases;
      if (r.lowSpeed && n->second->temporalError > 0) {
        g.tempErrSum += r.temporalError / n->second->temporalError;
        g.mtcdSum += n->second->mtcd > 0 ? r.mtcd / n->second->mtcd : 0.0;
        ++g.lowSpeedCases;
      }
      g.worstRatio = std::max(g.worstRatio, r.ghostWorstRatio);
      g.worstRecovery = std::max(g.worstRecovery, r.recoveryFrames);
      g.defaultAboveNone += r.rmse > n->second->rmse;
      const auto t = taa.find(r.scenario);
      g.defaultAboveTaa += t != taa.end() && r.rmse > t->second->rmse;
    }
  }
  return out;
}

}  // namespace

const std::vector<std::string>& corpusMotions() {
  static const std::vector<std::string> motions = [] {
    std::vector<std::string> m;
    for (const imu::MotionPreset& p : imu::motionPresets()) {
      if (p.inCorpus) m.push_back(p.name);
    }
    return m;
  }();
  return motions;
}

const std::vector<std::string>& corpusPictures() {
  // A photo, a natural texture, the procedural high-frequency pictures and the dark gradient.
  static const std::vector<std::string> pictures = {"astronaut", "brick",     "zoneplate",
                                                    "lines1px",  "smalltext", "darkgradient"};
  return pictures;
}

const std::vector<std::string>& corpusMethods() {
  static const std::vector<std::string> methods = {"none",   "fxaa",         "taa",     "taa+jitter",
                                                   "hmtaa",  "hybrid",       "default", "default+jitter",
                                                   "oracle", "oracle+jitter"};
  return methods;
}

std::string motionClassOf(const std::string& preset) {
  for (const imu::MotionPreset& p : imu::motionPresets()) {
    if (p.name == preset) return p.motionClass;
  }
  return preset;
}

double corpusStartSec(const std::string& preset, uint64_t seed, double windowSec) {
  std::string error;
  const auto stream = imu::makePreset(preset, seed, &error);
  if (!stream) return 0.0;
  const std::vector<double> changes = stream->motionChangeTimes();
  const double window = windowSec;
  auto inWindow = [&](double s) {
    return std::count_if(changes.begin(), changes.end(), [&](double t) { return t >= s && t <= s + window; });
  };
  double best = 0.0;
  auto bestCount = inWindow(0.0);
  for (double t : changes) {
    const double s = std::max(0.0, t - kPreRollSec);
    if (inWindow(s) > bestCount) {
      best = s;
      bestCount = inWindow(s);
    }
  }
  return best;
}

bool presetTranslates(const std::string& preset, uint64_t seed) {
  std::string error;
  const auto stream = imu::makePreset(preset, seed, &error);
  if (!stream) return false;
  const glm::vec3 start = stream->at(0.0).position;
  for (double t = 0.0; t <= stream->durationSec(); t += 0.05) {
    if (glm::length(stream->at(t).position - start) > 0.01f) return true;
  }
  return false;
}

std::vector<Scenario> corpusScenarios(const Options& o) {
  std::vector<Scenario> out;
  const bool fromCommandLine = !o.motions.empty();
  const std::vector<std::string> pictures = o.images.empty() ? corpusPictures() : o.images;
  const std::vector<std::string> motions = o.motions.empty() ? corpusMotions() : o.motions;
  const double windowSec = double(spanInPeriods(o.frames, o.dropFrames, o.seed)) / o.appHz;
  auto sceneWanted = [&](const std::string& scene) {  // --scenes narrows the corpus too
    return o.scenes.empty() || std::find(o.scenes.begin(), o.scenes.end(), scene) != o.scenes.end();
  };
  for (const std::string& motion : motions) {
    const bool translates = presetTranslates(motion, o.seed);
    const double start =
        fromCommandLine && o.startSec > 0 ? o.startSec : corpusStartSec(motion, o.seed, windowSec);
    auto add = [&](const std::string& scene, const std::string& picture, const std::string& pictureCls) {
      // Without depth too where the head translates (the first picture, the zone plate and the
      // scenes, to keep the corpus within its time), and always for the disocclusion scene.
      const bool noDepthToo =
          scene == "disocclusion" ||
          (translates && (scene != "imageviewer" || picture == pictures.front() || picture == "zoneplate"));
      for (const bool depth : {true, false}) {
        if (!depth && !noDepthToo) continue;
        Scenario s;
        s.scene = scene;
        s.motion = motion;
        s.picture = picture;
        s.motionClass = motionClassOf(motion);
        s.pictureClass = pictureCls;
        s.depthGiven = depth;
        s.startSec = start;
        s.sweeps = !o.methods.empty();  // sweeps named with --methods (ablations) run everywhere
        s.label =
            scene + "-" + motion + (isPictureScene(scene) ? "-" + picture : "") + (depth ? "" : "-nodepth");
        if (motion == "fastturn")
          s.leadSec = kPreRollSec;  // starts at t = 0: history from a still head first
        out.push_back(s);
      }
    };
    if (sceneWanted("imageviewer"))
      for (const std::string& p : pictures) add("imageviewer", p, pictureClass(p));
    // Head-locked content (scene_hud.h): not in the corpus, only when --scenes names it.
    if (!o.scenes.empty() && sceneWanted("hud"))
      for (const std::string& p : pictures) add("hud", p, pictureClass(p));
    for (const char* scene : {"thin", "moving", "disocclusion"}) {
      if (!sceneWanted(scene)) continue;
      // --ppd: a scene its depth stretch would put beyond the far plane is left out (scene.h,
      // makeScene; a head at the origin stands for the motions' first poses, which are near it).
      Scene probe;
      std::string refused;
      if (o.ppd > 0.0 && !makeScene(scene, "", TextureSet{}, ppdTangentScale(o.ppd, o.width), HeadPose{},
                                    &probe, &refused)) {
        if (motion == motions.front()) std::cerr << "steadyxr-eval: corpus: " << refused << "; left out\n";
        continue;
      }
      add(scene, pictures.front(), std::string("scene:") + scene);
    }
  }
  return out;
}

void printCorpusTable(const std::vector<ResultRow>& rows, std::ostream& out) {
  const auto g = groups(rows);
  out << "\nCorpus: mean RMSE relative to none's (%), per motion class and picture class; default's temporal "
         "error "
         "and MTCD relative to none's on the low-speed cases, worst frame / none, most frames to recover, "
         "and "
         "in how many cases default's mean RMSE is above none's and above taa's\n";
  out << std::left << std::setw(12) << "motion" << std::setw(20) << "pictures" << std::right << std::setw(4)
      << "n";
  for (const std::string& m : kTableMethods) out << std::setw(std::max<int>(8, int(m.size()) + 1)) << m;
  out << std::setw(8) << "TE%" << std::setw(8) << "MTCD%" << std::setw(8) << "worst" << std::setw(6)
      << "recov" << std::setw(7) << ">none" << std::setw(6) << ">taa"
      << "\n";
  for (const auto& [key, grp] : g) {
    out << std::left << std::setw(12) << key.first << std::setw(20) << key.second << std::right
        << std::setw(4) << grp.cases << std::fixed << std::setprecision(1);
    for (const std::string& m : kTableMethods) {
      const auto it = grp.rmseRatio.find(m);
      const int w = std::max<int>(8, int(m.size()) + 1);
      if (it == grp.rmseRatio.end() || it->second.second == 0)
        out << std::setw(w) << "-";
      else
        out << std::setw(w) << 100.0 * it->second.first / it->second.second;
    }
    if (grp.lowSpeedCases > 0)
      out << std::setw(8) << 100.0 * grp.tempErrSum / grp.lowSpeedCases << std::setw(8)
          << 100.0 * grp.mtcdSum / grp.lowSpeedCases;
    else
      out << std::setw(8) << "-" << std::setw(8) << "-";
    out << std::setprecision(2) << std::setw(8) << grp.worstRatio << std::setw(6) << grp.worstRecovery
        << std::setw(7) << grp.defaultAboveNone << std::setw(6) << grp.defaultAboveTaa << "\n";
    out.unsetf(std::ios::fixed);
  }
}

void writeCorpusCsv(const std::string& path, const std::vector<ResultRow>& rows) {
  std::ofstream f(path);
  f << "motion_class,picture_class,cases,method,mean_rmse_vs_none,low_speed_cases,default_temporal_error_vs_"
       "none,"
       "default_mtcd_vs_none,default_worst_frame_vs_none,default_max_recovery_frames,default_above_none,"
       "default_above_taa\n";
  for (const auto& [key, grp] : groups(rows)) {
    for (const auto& [method, sumN] : grp.rmseRatio) {
      f << key.first << ',' << key.second << ',' << grp.cases << ',' << method << ','
        << fmt(sumN.second ? sumN.first / sumN.second : 0.0, 6) << ',' << grp.lowSpeedCases << ','
        << fmt(grp.lowSpeedCases ? grp.tempErrSum / grp.lowSpeedCases : 0.0, 6) << ','
        << fmt(grp.lowSpeedCases ? grp.mtcdSum / grp.lowSpeedCases : 0.0, 6) << ',' << fmt(grp.worstRatio, 6)
        << ',' << grp.worstRecovery << ',' << grp.defaultAboveNone << ',' << grp.defaultAboveTaa << '\n';
    }
  }
}

}  // namespace steadyxr::eval
