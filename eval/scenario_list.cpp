// Which cases a run covers, and the textures they need.
#include "scenario_list.h"

#include "corpus.h"
#include "pictures.h"

#include <algorithm>
#include <filesystem>
#include <iostream>

namespace steadyxr::eval {

namespace {

const std::vector<std::string> kDefaultImages = {"astronaut", "camera", "coffee", "brick",
                                                 "grass",     "text",   "page"};

}  // namespace

std::vector<Scenario> buildScenarios(const Options& o, std::string* error) {
  std::vector<Scenario> out;
  const std::vector<std::string> images = o.images.empty() ? kDefaultImages : o.images;
  auto add = [&](const std::string& scene, const std::string& motion, bool trace,
                 const std::string& picture) {
    Scenario s;
    s.scene = scene;
    s.motion = motion;
    s.trace = trace;
    s.picture = picture;
    s.motionClass = trace ? "trace" : motionClassOf(motion);
    s.pictureClass = isPictureScene(scene) ? pictureClass(textureKey(picture)) : "scene:" + scene;
    const std::string motionLabel = trace ? std::filesystem::path(motion).stem().string() : motion;
    s.label = scene + "-" + motionLabel;
    if (isPictureScene(scene)) {  // appended: GCC 12 at -O3 warns (-Wrestrict) on "-" + std::string&&
      s.label += '-';
      s.label += textureKey(picture);
    }
    // The fast turn starts at once: give the filters history from a still head first.
    if (!trace && motion == "fastturn") s.leadSec = 0.5;
    out.push_back(s);
  };
  for (const std::string& sc : o.scenes) {
    if (std::find(sceneNames().begin(), sceneNames().end(), sc) == sceneNames().end()) {
      *error = "unknown scene '" + sc + "'";
      return {};
    }
  }
  if (o.corpus) return corpusScenarios(o);
  if (o.scenes.empty() && o.motions.empty()) {
    // The default suite: each scene with the head motion it is about.
    // Sweeps (extra points) only where they matter, to keep the default run to a few minutes.
    const size_t nImages =
        o.quick ? 1 : std::min<size_t>(images.size(), o.images.empty() ? 2 : images.size());
    for (size_t i = 0; i < nImages; ++i) add("imageviewer", "fixation", false, images[i]);
    // A zone plate up to Nyquist: the shimmer case a photo does not show (unless --images chose).
    if (!o.quick && o.images.empty()) add("imageviewer", "fixation", false, "zoneplate");
    add("imageviewer", "pursuit", false, images[0]);
    add("imageviewer", "fastturn", false, images[0]);
    add("thin", "fixation", false, images[0]);
    add("moving", "fixation", false, images[0]);
    add("disocclusion", "pursuit", false, images[0]);
    add("noisy", "fixation", false, images[0]);
    for (const std::string& tr : o.traces) add("imageviewer", tr, true, images[0]);
    // Methods named on the command line run everywhere: the user asked for them.
    for (size_t i = 0; i < out.size(); ++i)
      out[i].sweeps = !o.methods.empty() || i == 0 || out[i].motion == "fastturn";
    return out;
  }
  const std::vector<std::string> scenes = o.scenes.empty() ? sceneNames() : o.scenes;
  std::vector<std::pair<std::string, bool>> motions;
  for (const std::string& m : o.motions) motions.emplace_back(m, false);
  for (const std::string& t : o.traces) motions.emplace_back(t, true);
  if (motions.empty()) motions.emplace_back("fixation", false);
  for (const std::string& sc : scenes) {
    for (const auto& [m, trace] : motions) {
      if (isPictureScene(sc)) {
        for (const std::string& img : (o.images.empty() ? std::vector<std::string>{images[0]} : images)) {
          add(sc, m, trace, img);
        }
      } else {
        add(sc, m, trace, images[0]);
      }
    }
  }
  return out;
}

bool gatherTextures(const std::vector<Scenario>& scenarios, const Options& o, TextureSet* textures,
                    std::string* error) {
  Rgba8 white;
  white.width = white.height = 1;
  white.pixels = {255, 255, 255, 255};
  textures->images = {white};
  textures->names = {"white"};
  // The scenarios' pictures first: a path the user gave wins over a built-in name with its stem.
  for (const Scenario& s : scenarios) {
    if (textures->find(textureKey(s.picture)) != 0) continue;
    Rgba8 img;
    if (isProceduralPicture(s.picture)) {
      img = proceduralPicture(s.picture, o.height);
    } else if (!loadPicture(s.picture, o.picturesDir, &img, error)) {
      *error += " (nothing was measured)";
      return false;
    }
    textures->images.push_back(std::move(img));
    textures->names.push_back(textureKey(s.picture));
  }
  for (const char* name : {"brick", "grass", "text", "coffee", "camera"}) {
    if (textures->find(name) != 0) continue;
    std::string warning;
    textures->images.push_back(loadTextureOrFallback(name, o.picturesDir, &warning));
    textures->names.push_back(name);
    if (!warning.empty()) std::cerr << "steadyxr-eval: " << warning << "\n";
  }
  return true;
}

bool loadCases(const Options& o, std::vector<Scenario>* scenarios, TextureSet* textures, std::string* error) {
  *scenarios = buildScenarios(o, error);
  if (scenarios->empty()) {
    if (error->empty()) *error = "no scenarios";
    return false;
  }
  // Every texture any scenario needs, uploaded once (index 0 = white); before anything is written.
  return gatherTextures(*scenarios, o, textures, error);
}

bool loadMotion(const Scenario& sc, const Options& o, CaseMotion* motion, std::string* error) {
  std::string why;
  motion->stream = sc.trace ? imu::loadTrace(sc.motion, &why) : imu::makePreset(sc.motion, o.seed, &why);
  if (!motion->stream) {
    *error = "motion '" + sc.motion + "': " + why;
    return false;
  }
  motion->startSec = sc.startSec >= 0.0 ? sc.startSec : o.startSec;
  motion->firstFrameSec = motion->startSec - sc.leadSec;
  return true;
}

}  // namespace steadyxr::eval
