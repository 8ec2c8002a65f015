#include "suite.h"

#include "camera.h"
#include "image.h"
#include "metrics.h"
#include "renderer.h"
#include "scene.h"
#include "warp.h"

#include "steadyxr/core/filter.h"
#include "steadyxr/core/params.h"
#include "steadyxr/core/view_math.h"
#include "steadyxr/core/vulkan_context.h"
#include "steadyxr/imu/motion.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include <glm/glm.hpp>

namespace steadyxr::eval {

namespace {

constexpr float kIpdM = 0.064f;
constexpr float kNearZ = 0.05f;
constexpr float kFarZ = 100.0f;
const std::vector<std::string> kDefaultImages = {"astronaut", "camera", "coffee", "brick",
                                                 "grass",     "text",   "page"};

// Per-eye fov of a typical HMD: wider towards the temple than the nose (radians).
core::Fov eyeFov(int eye) {
  core::Fov f;
  f.angleUp = 0.80f;
  f.angleDown = -0.84f;
  f.angleLeft = eye == 0 ? -0.82f : -0.73f;
  f.angleRight = eye == 0 ? 0.73f : 0.82f;
  return f;
}

struct Scenario {
  std::string label;
  std::string scene;
  std::string motion;  // preset name or trace path
  bool trace = false;
  std::string picture;
  bool sweeps = true;    // run the parameter-sweep variants here
  double leadSec = 0.0;  // frames start this long before the stream (held at its t = 0 pose)
};

struct Variant {
  std::string name;
  core::Params params;
  int source = 1;  // 1 = the 1-sample render; 2 / 4 = MSAA
  bool sweep = false;
  std::unique_ptr<core::Filter> filter;
};

// Running sums of one (scenario, variant).
struct Accum {
  double sqErr = 0, sqN = 0, ssimSum = 0, ssimN = 0;
  double mtcdSum = 0, mtcdN = 0, mtcdDispSum = 0, mtcdDispN = 0;
  double sqErrDisp = 0, sqDispN = 0, errPxDisp = 0, errPxDispN = 0;
  double stereoSum = 0, stereoN = 0;
  double gpuTemporal = 0, gpuStereo = 0, gpuOther = 0, gpuN = 0;
  double timedWallMs = 0, timedGpuMs = 0;  // medians of the back-to-back timing frames
  double cpuUs = 0, cpuN = 0, renderMs = 0, renderN = 0;
  std::array<Image, 2> prev, prevDisplay;
};

struct ResultRow {
  std::string scenario, scene, motion, picture, method, filterMethod;
  bool sweep = false, stereo = false;
  int source = 1;
  double mtcd = 0, mtcdDisplay = 0, rmse = 0, ssim = 0, rmseDisplay = 0, errPxDisplayPct = 0;
  double stereoDiff = 0, stereoDiffGt = 0, stereoGap = 0;
  double gpuMs = 0, gpuTemporalMs = 0, gpuStereoMs = 0, gpuOtherMs = 0, renderMs = 0, costMs = 0, cpuUs = 0;
};

double safeDiv(double a, double b) {
  return b > 0 ? a / b : 0.0;
}

std::vector<std::string> defaultMethods(bool sweeps) {
  std::vector<std::string> m;
  for (const char* base : {"none", "fxaa", "msaa2", "msaa4", "taa", "hmtaa", "vtaa", "hybrid"}) {
    m.push_back(base);
    m.push_back(std::string(base) + "+stereo");
  }
  m.push_back("default");
  if (sweeps) {
    for (const char* s : {"hmtaa@hmax=10", "hmtaa@hmax=50", "hmtaa@wmin=0.15", "hmtaa@wmin=0.5",
                          "taa@alpha=0.05", "taa@alpha=0.2", "default@amin=0.02", "default@amin=0.15",
                          "default@beta=0.7", "default@catmull=1"}) {
      m.push_back(s);
    }
  }
  return m;
}

// "<method>[@key=value]...": a method name applyMethodName understands (or msaa2/msaa4[+stereo])
// with parameter overrides for sweeps.
bool parseVariant(const std::string& spec, Variant* v, std::string* error) {
  std::vector<std::string> parts;
  std::stringstream ss(spec);
  for (std::string p; std::getline(ss, p, '@');) parts.push_back(p);
  if (parts.empty()) {
    *error = "empty method";
    return false;
  }
  std::string base = parts[0];
  v->source = 1;
  for (int s : {2, 4}) {
    const std::string msaa = "msaa" + std::to_string(s);
    if (base == msaa || base == msaa + "+stereo") {
      // MSAA images go through the core as pass-through, or stereo blending only.
      v->source = s;
      base = base == msaa ? "none" : "stereo";
    }
  }
  auto params = core::applyMethodName(base);
  if (!params) {
    *error = "unknown method '" + parts[0] + "'";
    return false;
  }
  for (size_t i = 1; i < parts.size(); ++i) {
    const auto eq = parts[i].find('=');
    if (eq == std::string::npos) {
      *error = "bad parameter '" + parts[i] + "' in '" + spec + "'";
      return false;
    }
    const std::string key = parts[i].substr(0, eq);
    float value = 0.0f;
    try {
      value = std::stof(parts[i].substr(eq + 1));
    } catch (...) {
      *error = "bad value in '" + parts[i] + "'";
      return false;
    }
    if (key == "hmax")
      params->hMaxDegPerSec = value;
    else if (key == "wmin")
      params->wMin = value;
    else if (key == "wlb")
      params->wLowerBound = value;
    else if (key == "amin")
      params->vtaaAlphaMin = value;
    else if (key == "alpha")
      params->taaAlpha = value;
    else if (key == "gamma")
      params->taaClipGamma = value;
    else if (key == "beta")
      params->stereoBetaMin = value;
    else if (key == "d")
      params->sampleD[0] = value;
    else if (key == "catmull")
      params->historyFilter = value != 0.0f ? core::HistoryFilter::CatmullRom : core::HistoryFilter::Bilinear;
    else if (key == "floor")  // steady's ablation switches and constants (core::Params)
      params->steadyAlphaFloor = value;
    else if (key == "conf")
      params->steadyConfidence = value != 0.0f;
    else if (key == "reject")
      params->steadyClipRejects = value != 0.0f;
    else if (key == "blur")
      params->steadyBlurBudgetPx2 = value;
    else if (key == "footprint")
      params->steadyFootprint = value;
    else if (key == "near")
      params->steadyNearestDepthM = value;
    else if (key == "interp")
      params->steadyInterpolated = value != 0.0f;
    else {
      *error = "unknown parameter '" + key +
               "' (hmax, wmin, wlb, amin, alpha, gamma, beta, d, catmull, floor, conf, reject, blur, "
               "footprint, near, interp)";
      return false;
    }
    v->sweep = true;
  }
  const std::string problem = core::validate(*params);
  if (!problem.empty()) {
    *error = "method '" + spec + "': " + problem;
    return false;
  }
  v->params = *params;
  v->name = spec;
  return true;
}

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
    const std::string motionLabel = trace ? std::filesystem::path(motion).stem().string() : motion;
    s.label = scene + "-" + motionLabel;
    if (scene == "imageviewer" || scene == "noisy") s.label += "-" + textureKey(picture);
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
  if (o.scenes.empty() && o.motions.empty()) {
    // The default suite: each scene with the head motion it is about.
    // Sweeps (extra points) only where they matter, to keep the default run to a few minutes.
    const size_t nImages =
        o.quick ? 1 : std::min<size_t>(images.size(), o.images.empty() ? 2 : images.size());
    for (size_t i = 0; i < nImages; ++i) add("imageviewer", "fixation", false, images[i]);
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
      if (sc == "imageviewer" || sc == "noisy") {
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

class Progress {
 public:
  Progress(bool enabled, int total)
      : enabled_(enabled), total_(total), start_(std::chrono::steady_clock::now()) {}
  void update(int done, const std::string& what) {
    if (!enabled_) return;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double eta = done > 0 ? elapsed * (total_ - done) / done : 0.0;
    const int width = 30, filled = total_ > 0 ? width * done / total_ : width;
    std::fprintf(stderr, "\r[%s%s] %3d%% %-38.38s %5.0fs left ", std::string(filled, '#').c_str(),
                 std::string(width - filled, ' ').c_str(), total_ > 0 ? 100 * done / total_ : 100,
                 what.c_str(), eta);
    std::fflush(stderr);
  }
  void finish() {
    if (enabled_) std::fprintf(stderr, "\n");
  }

 private:
  bool enabled_;
  int total_;
  std::chrono::steady_clock::time_point start_;
};

struct HeadPose {
  glm::quat orientation{1, 0, 0, 0};
  glm::vec3 position{0.0f};
};

std::array<EyeCamera, 2> eyeCameras(const HeadPose& head, int w, int h) {
  std::array<EyeCamera, 2> cams;
  for (int eye = 0; eye < 2; ++eye) {
    core::Pose p;
    p.orientation = head.orientation;
    p.position = head.position + head.orientation * glm::vec3(eye == 0 ? -kIpdM / 2 : kIpdM / 2, 0.0f, 0.0f);
    cams[eye] = makeEyeCamera(p, eyeFov(eye), w, h, kNearZ, kFarZ);
  }
  return cams;
}

std::string csvEscape(const std::string& s) {
  return s.find(',') == std::string::npos ? s : "\"" + s + "\"";
}

std::string fmt(double v, int prec = 5) {
  std::ostringstream os;
  os << std::setprecision(prec) << v;
  return os.str();
}

void writeResultsCsv(const std::string& path, const std::vector<ResultRow>& rows) {
  std::ofstream f(path);
  f << "scenario,scene,motion,picture,method,filter_method,sweep,stereo,samples,mtcd,mtcd_display,rmse,ssim,"
       "rmse_display,error_pixels_display_pct,stereo_diff,stereo_diff_gt,stereo_gap,gpu_ms,gpu_temporal_ms,"
       "gpu_stereo_ms,gpu_other_ms,render_ms,cost_ms,cpu_us\n";
  for (const ResultRow& r : rows) {
    f << csvEscape(r.scenario) << ',' << r.scene << ',' << csvEscape(r.motion) << ',' << r.picture << ','
      << r.method << ',' << r.filterMethod << ',' << r.sweep << ',' << r.stereo << ',' << r.source << ','
      << fmt(r.mtcd, 6) << ',' << fmt(r.mtcdDisplay, 6) << ',' << fmt(r.rmse, 6) << ',' << fmt(r.ssim, 6)
      << ',' << fmt(r.rmseDisplay, 6) << ',' << fmt(r.errPxDisplayPct, 6) << ',' << fmt(r.stereoDiff, 6)
      << ',' << fmt(r.stereoDiffGt, 6) << ',' << fmt(r.stereoGap, 6) << ',' << fmt(r.gpuMs, 6) << ','
      << fmt(r.gpuTemporalMs, 6) << ',' << fmt(r.gpuStereoMs, 6) << ',' << fmt(r.gpuOtherMs, 6) << ','
      << fmt(r.renderMs, 6) << ',' << fmt(r.costMs, 6) << ',' << fmt(r.cpuUs, 6) << '\n';
  }
}

std::string jsonStr(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    o += c;
  }
  return o + "\"";
}

struct TargetCheck {
  std::string name, detail;
  bool met = false;
  bool evaluated = false;
};

const ResultRow* findRow(const std::vector<ResultRow>& rows, const std::string& scenario,
                         const std::string& m) {
  for (const ResultRow& r : rows) {
    if (r.scenario == scenario && r.method == m) return &r;
  }
  return nullptr;
}

std::vector<TargetCheck> checkTargets(const std::vector<ResultRow>& rows,
                                      const std::vector<Scenario>& scenarios,
                                      const std::string& defaultTemporal) {
  std::vector<TargetCheck> out;
  // 1. MTCD of the default <= 40 % of none, image viewer under fixation.
  {
    TargetCheck t{"default MTCD <= 40% of none (imageviewer, fixation)", "", true, false};
    for (const Scenario& s : scenarios) {
      if (s.scene != "imageviewer" || s.motion != "fixation") continue;
      const ResultRow *d = findRow(rows, s.label, "default"), *n = findRow(rows, s.label, "none");
      if (!d || !n) continue;
      const double ratio = safeDiv(d->mtcd, n->mtcd);
      t.evaluated = true;
      t.met = t.met && ratio <= 0.40;
      t.detail += s.label + ": " + fmt(100 * ratio, 3) + "%; ";
    }
    out.push_back(t);
  }
  // 2. RMSE below taa in every scenario, >= 20 % below on average.
  {
    TargetCheck t{"default RMSE < taa everywhere, >= 20% below on average", "", true, false};
    double sum = 0;
    int n = 0;
    for (const Scenario& s : scenarios) {
      const ResultRow *d = findRow(rows, s.label, "default"), *a = findRow(rows, s.label, "taa");
      if (!d || !a) continue;
      const double rel = safeDiv(d->rmse, a->rmse);
      t.evaluated = true;
      t.met = t.met && rel < 1.0;
      sum += 1.0 - rel;
      ++n;
      t.detail += s.label + ": " + fmt(100 * (1 - rel), 3) + "% below; ";
    }
    if (n > 0) {
      t.met = t.met && sum / n >= 0.20;
      t.detail += "average " + fmt(100 * sum / n, 3) + "% below";
    }
    out.push_back(t);
  }
  // 3. No ghosting: fast turn and moving object, RMSE <= none's + 5 %.
  {
    TargetCheck t{"no ghosting: default RMSE <= none +5% (fastturn, moving)", "", true, false};
    for (const Scenario& s : scenarios) {
      if (s.motion != "fastturn" && s.scene != "moving") continue;
      const ResultRow *d = findRow(rows, s.label, "default"), *n = findRow(rows, s.label, "none");
      if (!d || !n) continue;
      const double rel = safeDiv(d->rmse, n->rmse);
      t.evaluated = true;
      t.met = t.met && rel <= 1.05;
      t.detail += s.label + ": " + fmt(100 * rel, 4) + "% of none; ";
    }
    out.push_back(t);
  }
  // 4. Stereo pass: stereo difference >= 30 % closer to ground truth's, no rise in RMSE.
  {
    TargetCheck t{"stereo pass: stereo gap -30% or better, RMSE not higher (" + defaultTemporal + ")", "",
                  true, false};
    for (const Scenario& s : scenarios) {
      const ResultRow *w = findRow(rows, s.label, defaultTemporal + "+stereo"),
                      *wo = findRow(rows, s.label, defaultTemporal);
      if (!w || !wo) continue;
      const double closer = 1.0 - safeDiv(w->stereoGap, wo->stereoGap);
      const bool ok = closer >= 0.30 && w->rmse <= wo->rmse * 1.0005;
      t.evaluated = true;
      t.met = t.met && ok;
      t.detail += s.label + ": gap " + fmt(100 * closer, 3) + "% closer, RMSE " +
                  fmt(100 * (safeDiv(w->rmse, wo->rmse) - 1), 3) + "%; ";
    }
    out.push_back(t);
  }
  for (TargetCheck& t : out) {
    if (!t.evaluated) {
      t.met = false;
      t.detail = "not evaluated (scenario or method not in this run)";
    }
  }
  return out;
}

void writeJson(const std::string& path, const Options& o, const std::vector<ResultRow>& rows,
               const std::vector<TargetCheck>& targets, const std::string& device, double seconds) {
  std::ofstream f(path);
  f << "{\n  \"config\": {\"width\": " << o.width << ", \"height\": " << o.height
    << ", \"frames\": " << o.frames << ", \"seed\": " << o.seed << ", \"app_hz\": " << o.appHz
    << ", \"display_hz\": " << o.displayHz << ", \"gt_samples_per_pixel\": " << o.gtGrid * o.gtGrid
    << ", \"ipd_m\": " << kIpdM << ", \"error_threshold\": " << o.errorThreshold
    << ", \"device\": " << jsonStr(device)
    << ", \"color_space\": \"display-encoded (sRGB) 8-bit values scaled to [0,1]; MTCD in 8-bit code values\""
    << ", \"wall_seconds\": " << fmt(seconds, 4) << "},\n  \"results\": [\n";
  for (size_t i = 0; i < rows.size(); ++i) {
    const ResultRow& r = rows[i];
    f << "    {\"scenario\": " << jsonStr(r.scenario) << ", \"scene\": " << jsonStr(r.scene)
      << ", \"motion\": " << jsonStr(r.motion) << ", \"picture\": " << jsonStr(r.picture)
      << ", \"method\": " << jsonStr(r.method) << ", \"filter_method\": " << jsonStr(r.filterMethod)
      << ", \"sweep\": " << (r.sweep ? "true" : "false") << ", \"stereo\": " << (r.stereo ? "true" : "false")
      << ", \"samples\": " << r.source << ", \"mtcd\": " << fmt(r.mtcd, 6)
      << ", \"mtcd_display\": " << fmt(r.mtcdDisplay, 6) << ", \"rmse\": " << fmt(r.rmse, 6)
      << ", \"ssim\": " << fmt(r.ssim, 6) << ", \"rmse_display\": " << fmt(r.rmseDisplay, 6)
      << ", \"error_pixels_display_pct\": " << fmt(r.errPxDisplayPct, 6)
      << ", \"stereo_diff\": " << fmt(r.stereoDiff, 6) << ", \"stereo_diff_gt\": " << fmt(r.stereoDiffGt, 6)
      << ", \"stereo_gap\": " << fmt(r.stereoGap, 6) << ", \"gpu_ms\": " << fmt(r.gpuMs, 6)
      << ", \"gpu_temporal_ms\": " << fmt(r.gpuTemporalMs, 6)
      << ", \"gpu_stereo_ms\": " << fmt(r.gpuStereoMs, 6) << ", \"gpu_other_ms\": " << fmt(r.gpuOtherMs, 6)
      << ", \"render_ms\": " << fmt(r.renderMs, 6) << ", \"cost_ms\": " << fmt(r.costMs, 6)
      << ", \"cpu_us\": " << fmt(r.cpuUs, 6) << "}" << (i + 1 < rows.size() ? "," : "") << "\n";
  }
  f << "  ],\n  \"targets\": [\n";
  for (size_t i = 0; i < targets.size(); ++i) {
    f << "    {\"target\": " << jsonStr(targets[i].name)
      << ", \"evaluated\": " << (targets[i].evaluated ? "true" : "false")
      << ", \"met\": " << (targets[i].met ? "true" : "false")
      << ", \"detail\": " << jsonStr(targets[i].detail) << "}" << (i + 1 < targets.size() ? "," : "") << "\n";
  }
  f << "  ]\n}\n";
}

}  // namespace

int runSuite(const Options& o) {
  const auto wallStart = std::chrono::steady_clock::now();
  std::string error;
  const std::vector<Scenario> scenarios = buildScenarios(o, &error);
  if (scenarios.empty()) {
    std::cerr << "steadyxr-eval: " << (error.empty() ? "no scenarios" : error) << "\n";
    return 2;
  }
  // Created first so that it outlives every filter and renderer below.
  core::OwnedContextOptions co;
  co.enableValidation = o.validation;
  co.applicationName = "steadyxr-eval";
  auto ctx = core::VulkanContext::createOwned(co, &error);
  if (!ctx) {
    std::cerr << "steadyxr-eval: no Vulkan context: " << error << "\n";
    return 1;
  }
  const std::string device = ctx->properties().deviceName;
  std::vector<Variant> variants;
  for (const std::string& spec : o.methods.empty() ? defaultMethods(o.sweeps && !o.quick) : o.methods) {
    Variant v;
    if (!parseVariant(spec, &v, &error)) {
      std::cerr << "steadyxr-eval: " << error << "\n";
      return 2;
    }
    variants.push_back(std::move(v));
  }
  std::filesystem::create_directories(o.outDir);
  std::filesystem::create_directories(o.outDir + "/crops");

  // Every texture any scenario needs, uploaded once (index 0 = white).
  TextureSet textures;
  {
    Rgba8 white;
    white.width = white.height = 1;
    white.pixels = {255, 255, 255, 255};
    textures.images.push_back(white);
    textures.names.push_back("white");
    // The scenarios' pictures first: a path the user gave wins over a built-in name with its stem.
    std::vector<std::string> wanted;
    for (const Scenario& s : scenarios) wanted.push_back(s.picture);
    for (const char* name : {"brick", "grass", "text", "coffee", "camera"}) wanted.push_back(name);
    for (const std::string& name : wanted) {
      if (textures.find(textureKey(name)) != 0) continue;
      std::string warning;
      textures.images.push_back(loadTextureOrFallback(name, o.picturesDir, &warning));
      textures.names.push_back(textureKey(name));
      if (!warning.empty()) std::cerr << "steadyxr-eval: " << warning << "\n";
    }
  }
  auto renderer = SceneRenderer::create(*ctx, o.width, o.height, textures.images, &error);
  if (!renderer) {
    std::cerr << "steadyxr-eval: renderer: " << error << "\n";
    return 1;
  }
  std::vector<std::string> skipped;
  std::erase_if(variants, [&](const Variant& v) {
    if (renderer->supportsSamples(v.source)) return false;
    skipped.push_back(v.name);
    std::cerr << "steadyxr-eval: skipping '" << v.name << "': " << v.source << "x MSAA not supported by "
              << device << "\n";
    return true;
  });
  for (Variant& v : variants) {
    v.filter = core::Filter::create(*ctx, v.params, &error);
    if (!v.filter) {
      std::cerr << "steadyxr-eval: filter '" << v.name << "': " << error << "\n";
      return 1;
    }
  }
  const std::string defaultTemporal = std::string(core::toString(core::kDefaultTemporalMethod));

  std::vector<ResultRow> rows;
  std::ofstream series(o.outDir + "/timeseries.csv");
  series << "scenario,method,frame,t_s,head_speed_deg_s,object_speed_m_s,mtcd,rmse,ssim,stereo_diff,"
            "stereo_diff_gt,mtcd_display,rmse_display\n";
  std::ofstream warpCsv(o.outDir + "/warp_errors.csv");
  warpCsv << "scenario,frame,step,extrapolation_ms,head_speed_deg_s,object_speed_m_s,mode,error_pixels,"
             "error_fraction\n";

  const double dt = 1.0 / o.appHz;
  const int ratio = std::max(1, int(std::lround(o.displayHz / o.appHz)));
  const int totalFrames = int(scenarios.size()) * o.frames;
  Progress progress(o.progress, totalFrames);
  int framesDone = 0;
  const size_t nPix = size_t(o.width) * o.height;

  for (const Scenario& sc : scenarios) {
    Scene scene;
    if (!makeScene(sc.scene, sc.picture, textures, &scene, &error)) {
      std::cerr << "steadyxr-eval: " << error << "\n";
      return 2;
    }
    std::unique_ptr<imu::MotionStream> stream =
        sc.trace ? imu::loadTrace(sc.motion, &error) : imu::makePreset(sc.motion, o.seed, &error);
    if (!stream) {
      std::cerr << "steadyxr-eval: motion '" << sc.motion << "': " << error << "\n";
      return 2;
    }
    auto headAt = [&](double t) {
      const imu::MotionState m = stream->at(std::max(0.0, t));
      return HeadPose{glm::normalize(m.orientation), m.position + scene.headOffset(t)};
    };
    std::vector<Accum> acc(variants.size());
    for (Variant& v : variants) v.filter->reset();
    double gtStereoSum = 0, gtStereoN = 0;
    HeadPose prevHead = headAt(o.startSec - sc.leadSec - dt);
    std::array<Image, 2> lastGt;
    std::vector<std::array<Image, 2>> lastOut(variants.size());
    std::vector<std::optional<core::StereoFrame>> lastFrame(variants.size());

    for (int f = 0; f < o.frames; ++f) {
      const double t = o.startSec - sc.leadSec + f * dt;
      const HeadPose head = headAt(t);
      const float headSpeed = core::angleBetweenDeg(prevHead.orientation, head.orientation) / float(dt);
      prevHead = head;
      const auto cams = eyeCameras(head, o.width, o.height);
      const float objSpeed = scene.objectSpeed(t);

      // The app's images (1 sample), MSAA baselines and the ground truth, both eyes.
      std::array<RenderedView, 2> base;
      std::array<Image, 2> gt;
      std::array<std::array<Image, 2>, 2> msaa;
      double baseMs = 0;
      std::array<double, 2> msaaMs{0, 0};
      bool needMsaa[2] = {false, false};
      for (const Variant& v : variants) {
        if (v.source == 2) needMsaa[0] = true;
        if (v.source == 4) needMsaa[1] = true;
      }
      for (int eye = 0; eye < 2; ++eye) {
        DrawList draws = scene.drawsAt(t);
        draws.noiseSeed = uint32_t(f * 2 + eye + 1);
        if (o.noise > 0.0f) draws.noiseAmplitude = o.noise;
        double ms = 0;
        if (!renderer->renderBase(eye, cams[eye], draws, &base[eye], &ms, &error)) {
          std::cerr << "steadyxr-eval: render: " << error << "\n";
          return 1;
        }
        baseMs += ms;
        for (int i = 0; i < 2; ++i) {
          if (!needMsaa[i]) continue;
          ms = 0;
          if (!renderer->renderMsaa(i == 0 ? 2 : 4, eye, cams[eye], draws, &msaa[i][eye], &ms, &error)) {
            std::cerr << "steadyxr-eval: msaa render: " << error << "\n";
            return 1;
          }
          msaaMs[i] += ms;
        }
        if (!renderer->renderGroundTruth(cams[eye], draws, o.gtGrid, &gt[eye], &error)) {
          std::cerr << "steadyxr-eval: ground truth: " << error << "\n";
          return 1;
        }
      }
      const StereoDifference gtSd =
          stereoDifference(gt[0], base[0].depth, cams[0], gt[1], base[1].depth, cams[1]);
      gtStereoSum += gtSd.meanSquared;
      gtStereoN += 1;

      // Display stage references: head poses and ground truth at the display times in between.
      std::vector<std::array<EyeCamera, 2>> dispCams(ratio);
      std::vector<std::array<Image, 2>> dispGt(ratio);
      for (int k = 0; k < ratio; ++k) {
        const double td = t + k / o.displayHz;
        dispCams[k] = k == 0 ? cams : eyeCameras(headAt(td), o.width, o.height);
        for (int eye = 0; eye < 2; ++eye) {
          if (k == 0) {
            dispGt[k][eye] = gt[eye];
            continue;
          }
          if (!renderer->renderGroundTruth(dispCams[k][eye], scene.drawsAt(td), o.gtGrid, &dispGt[k][eye],
                                           &error)) {
            std::cerr << "steadyxr-eval: ground truth: " << error << "\n";
            return 1;
          }
        }
      }

      for (size_t vi = 0; vi < variants.size(); ++vi) {
        Variant& v = variants[vi];
        Accum& a = acc[vi];
        if (v.sweep && !sc.sweeps) continue;
        core::StereoFrame frame;
        for (int eye = 0; eye < 2; ++eye) {
          core::ViewFrame& view = frame.views[eye];
          view.color = v.source == 1 ? renderer->baseColor(eye) : renderer->msaaColor(v.source, eye);
          view.depth = renderer->baseDepth(eye, kNearZ, kFarZ);
          view.pose = cams[eye].pose;
          view.fov = cams[eye].fov;
        }
        frame.viewCount = 2;
        frame.displayTimeNs = int64_t(std::llround((t + sc.leadSec + 1.0) * 1e9));  // positive, monotonic
        frame.headSpeedDegPerSec = headSpeed;
        frame.reset = f == 0;
        core::StereoOutput output;
        output.views = {renderer->output(0), renderer->output(1)};
        const auto c0 = std::chrono::steady_clock::now();
        const bool ok = v.filter->submit(frame, output, &error);
        const auto c1 = std::chrono::steady_clock::now();
        v.filter->waitIdle();
        if (f == o.frames - 1) lastFrame[vi] = frame;
        if (!ok) {
          std::cerr << "\nsteadyxr-eval: filter '" << v.name << "' submit failed: " << error << "\n";
          return 1;
        }
        // Timings skip the first frames: lavapipe compiles shaders on first use.
        const bool warm = f >= std::min(2, o.frames - 1);
        if (warm) {
          a.cpuUs += std::chrono::duration<double, std::micro>(c1 - c0).count();
          a.cpuN += 1;
        }
        if (auto tm = v.filter->lastTimings(); tm && warm) {
          a.gpuTemporal += tm->temporalMs;
          a.gpuStereo += tm->stereoMs;
          a.gpuOther += tm->otherMs;
          a.gpuN += 1;
        }
        if (warm) {
          a.renderMs += v.source == 1 ? baseMs : msaaMs[v.source == 2 ? 0 : 1];
          a.renderN += 1;
        }
        std::array<Image, 2> out;
        for (int eye = 0; eye < 2; ++eye) {
          if (!renderer->readOutput(eye, &out[eye], &error)) {
            std::cerr << "steadyxr-eval: readback: " << error << "\n";
            return 1;
          }
        }
        double frameSq = 0, frameSsim = 0, frameMtcd = -1, frameMtcdDisp = -1, frameSqDisp = 0;
        for (int eye = 0; eye < 2; ++eye) {
          const double mse = meanSquaredError(out[eye], gt[eye]);
          frameSq += mse / 2;
          a.sqErr += mse * nPix * 3;
          a.sqN += double(nPix) * 3;
          const double s = ssim(out[eye], gt[eye]);
          frameSsim += s / 2;
          a.ssimSum += s;
          a.ssimN += 1;
          if (!a.prev[eye].empty()) {
            const double m = 255.0 * temporalColorDifference(a.prev[eye], out[eye]);
            frameMtcd = (frameMtcd < 0 ? 0 : frameMtcd) + m / 2;
            a.mtcdSum += m;
            a.mtcdN += 1;
          }
          // Display stage (a): the runtime's rotational timewarp of this frame until the next one.
          for (int k = 0; k < ratio; ++k) {
            const Image shown = k == 0 ? out[eye] : rotationalTimewarp(out[eye], cams[eye], dispCams[k][eye]);
            const double dmse = meanSquaredError(shown, dispGt[k][eye]);
            frameSqDisp += dmse / (2 * ratio);
            a.sqErrDisp += dmse;
            a.sqDispN += 1;
            a.errPxDisp += double(errorPixels(shown, dispGt[k][eye], o.errorThreshold)) / double(nPix);
            a.errPxDispN += 1;
            if (!a.prevDisplay[eye].empty()) {
              const double m = 255.0 * temporalColorDifference(a.prevDisplay[eye], shown);
              frameMtcdDisp = (frameMtcdDisp < 0 ? 0 : frameMtcdDisp) + m / (2 * ratio);
              a.mtcdDispSum += m;
              a.mtcdDispN += 1;
            }
            a.prevDisplay[eye] = shown;
          }
        }
        const StereoDifference sd =
            stereoDifference(out[0], base[0].depth, cams[0], out[1], base[1].depth, cams[1]);
        a.stereoSum += sd.meanSquared;
        a.stereoN += 1;
        series << csvEscape(sc.label) << ',' << v.name << ',' << f << ',' << fmt(t, 6) << ','
               << fmt(headSpeed, 5) << ',' << fmt(objSpeed, 5) << ','
               << (frameMtcd < 0 ? "" : fmt(frameMtcd, 6)) << ',' << fmt(std::sqrt(frameSq), 6) << ','
               << fmt(frameSsim, 6) << ',' << fmt(sd.meanSquared, 6) << ',' << fmt(gtSd.meanSquared, 6) << ','
               << (frameMtcdDisp < 0 ? "" : fmt(frameMtcdDisp, 6)) << ',' << fmt(std::sqrt(frameSqDisp), 6)
               << '\n';
        a.prev = out;
        if (f == o.frames - 1) lastOut[vi] = std::move(out);
      }
      if (f == o.frames - 1) lastGt = gt;

      // Seed 004 study (left eye, the app's own image): extrapolate k display frames ahead by
      // (a) rotational timewarp and (b) forward depth-image warping with per-pixel motion, and
      // count pixels that differ from the frame rendered at that time. Runs after the filters:
      // it reuses the 1-sample render target.
      for (int k = 1; k <= o.warpSteps; ++k) {
        const double td = t + k / o.displayHz;
        const auto dc = eyeCameras(headAt(td), o.width, o.height);
        DrawList draws = scene.drawsAt(td);
        draws.noiseSeed = uint32_t(f * 2 + 1);
        if (o.noise > 0.0f) draws.noiseAmplitude = o.noise;
        RenderedView truth;
        if (!renderer->renderBase(0, dc[0], draws, &truth, nullptr, &error)) {
          std::cerr << "steadyxr-eval: render: " << error << "\n";
          return 1;
        }
        const Image tw = rotationalTimewarp(base[0].color, cams[0], dc[0]);
        const MotionField motion = [&](const glm::vec3& p) { return scene.motion(p, t, dt); };
        const Image fw = forwardDepthWarp(base[0].color, base[0].depth, cams[0], dc[0], motion,
                                          float((k / o.displayHz) / dt));
        for (int mode = 0; mode < 2; ++mode) {
          const int64_t e = errorPixels(mode == 0 ? tw : fw, truth.color, o.errorThreshold);
          warpCsv << csvEscape(sc.label) << ',' << f << ',' << k << ',' << fmt(1000.0 * k / o.displayHz, 5)
                  << ',' << fmt(headSpeed, 5) << ',' << fmt(objSpeed, 5) << ','
                  << (mode == 0 ? "timewarp" : "depthwarp") << ',' << e << ','
                  << fmt(double(e) / double(nPix), 6) << '\n';
        }
      }
      progress.update(++framesDone, sc.label + " " + std::to_string(f + 1) + "/" + std::to_string(o.frames));
    }

    // Cost: each method's frames back to back on the scenario's last frame. Interleaved with a
    // score of other methods, lavapipe's cache of compiled shaders (capped by instruction count)
    // evicts and recompiles the large temporal shaders on every frame (measured: hmtaa 13 ms
    // alone, ~600 ms interleaved at 256x256), which would be billed to the method.
    for (size_t vi = 0; vi < variants.size(); ++vi) {
      Variant& v = variants[vi];
      if ((v.sweep && !sc.sweeps) || !lastFrame[vi]) continue;
      constexpr int kWarm = 2, kTimed = 6;
      std::vector<double> wall, gpu;
      for (int k = 0; k < kWarm + kTimed; ++k) {
        core::StereoOutput output;
        output.views = {renderer->output(0), renderer->output(1)};
        const auto c0 = std::chrono::steady_clock::now();
        const bool ok = v.filter->submit(*lastFrame[vi], output, &error);
        v.filter->waitIdle();
        const auto c1 = std::chrono::steady_clock::now();
        if (!ok) {
          std::cerr << "\nsteadyxr-eval: filter '" << v.name << "' submit failed: " << error << "\n";
          return 1;
        }
        if (k < kWarm) continue;
        wall.push_back(std::chrono::duration<double, std::milli>(c1 - c0).count());
        if (auto tm = v.filter->lastTimings()) gpu.push_back(tm->totalMs);
      }
      auto median = [](std::vector<double> x) {
        if (x.empty()) return 0.0;
        std::nth_element(x.begin(), x.begin() + x.size() / 2, x.end());
        return x[x.size() / 2];
      };
      acc[vi].timedWallMs = median(wall);
      acc[vi].timedGpuMs = median(gpu);
    }

    // Rows of this scenario.
    const double gtStereo = safeDiv(gtStereoSum, gtStereoN);
    for (size_t vi = 0; vi < variants.size(); ++vi) {
      const Variant& v = variants[vi];
      const Accum& a = acc[vi];
      if (v.sweep && !sc.sweeps) continue;
      ResultRow r;
      r.scenario = sc.label;
      r.scene = sc.scene;
      r.motion = sc.trace ? std::filesystem::path(sc.motion).stem().string() : sc.motion;
      r.picture = (sc.scene == "imageviewer" || sc.scene == "noisy") ? textureKey(sc.picture) : "";
      r.method = v.name;
      r.filterMethod = core::methodName(v.params);
      r.sweep = v.sweep;
      r.stereo = v.params.stereo;
      r.source = v.source;
      r.mtcd = safeDiv(a.mtcdSum, a.mtcdN);
      r.mtcdDisplay = safeDiv(a.mtcdDispSum, a.mtcdDispN);
      r.rmse = std::sqrt(safeDiv(a.sqErr, a.sqN));
      r.ssim = safeDiv(a.ssimSum, a.ssimN);
      r.rmseDisplay = std::sqrt(safeDiv(a.sqErrDisp, a.sqDispN));
      r.errPxDisplayPct = 100.0 * safeDiv(a.errPxDisp, a.errPxDispN);
      r.stereoDiff = safeDiv(a.stereoSum, a.stereoN);
      r.stereoDiffGt = gtStereo;
      r.stereoGap = std::fabs(r.stereoDiff - gtStereo);
      // lavapipe's timestamps miss dispatches that no barrier waits for (measured: hybrid 0.1 ms
      // by timestamps, 3.5 ms from submit to idle, at 256x256), and its "GPU" is this CPU anyway:
      // there the cost is the wall time from submit to idle. Real GPUs: timestamps.
      r.gpuMs = ctx->isCpuDevice() ? a.timedWallMs : a.timedGpuMs;
      r.gpuTemporalMs = safeDiv(a.gpuTemporal, a.gpuN);
      r.gpuStereoMs = safeDiv(a.gpuStereo, a.gpuN);
      r.gpuOtherMs = safeDiv(a.gpuOther, a.gpuN);
      r.renderMs = safeDiv(a.renderMs, a.renderN);
      r.cpuUs = safeDiv(a.cpuUs, a.cpuN);
      rows.push_back(r);
    }
    // Cost = the filter's GPU time + the render time above the 1-sample render (MSAA's price).
    double baseRender = 0;
    for (const ResultRow& r : rows) {
      if (r.scenario == sc.label && r.source == 1) baseRender = r.renderMs;
    }
    for (ResultRow& r : rows) {
      if (r.scenario == sc.label) r.costMs = r.gpuMs + std::max(0.0, r.renderMs - baseRender);
    }

    // Magnified crops (seed 003 Fig. 4): ground truth and methods, with |difference| x4 below.
    {
      const std::vector<std::string> shown = {"none", "fxaa", "msaa4", "taa", "hmtaa", "vtaa", "default"};
      std::vector<std::pair<std::string, const Image*>> tiles = {{"gt", &lastGt[0]}};
      for (const std::string& m : shown) {
        for (size_t vi = 0; vi < variants.size(); ++vi) {
          if (variants[vi].name == m && !lastOut[vi][0].empty()) tiles.emplace_back(m, &lastOut[vi][0]);
        }
      }
      const int cw = std::max(8, o.width / 5), ch = std::max(8, o.height / 5), scale = 4;
      const int x0 = o.width / 2 - cw / 2, y0 = o.height / 2 - ch / 2;
      Image canvas(int(tiles.size()) * (cw * scale + 4), 2 * (ch * scale + 4), 1.0f);
      for (size_t i = 0; i < tiles.size(); ++i) {
        blit(&canvas, cropMagnify(*tiles[i].second, x0, y0, cw, ch, scale), int(i) * (cw * scale + 4), 0);
        blit(&canvas, cropMagnify(differenceImage(*tiles[i].second, lastGt[0], 4.0f), x0, y0, cw, ch, scale),
             int(i) * (cw * scale + 4), ch * scale + 4);
      }
      savePng(o.outDir + "/crops/" + sc.label + ".png", canvas, &error);
      std::ofstream legend(o.outDir + "/crops/" + sc.label + ".txt");
      legend << "columns (left to right):";
      for (const auto& t : tiles) legend << ' ' << t.first;
      legend << "\nrow 1: " << cw << "x" << ch << " px crop of the left eye at the last frame, magnified x"
             << scale << "; row 2: |image - ground truth| x4\n";
      savePng(o.outDir + "/crops/" + sc.label + "_full_gt.png", lastGt[0], &error);
      for (size_t vi = 0; vi < variants.size(); ++vi) {
        if ((variants[vi].name == "none" || variants[vi].name == "default") && !lastOut[vi][0].empty()) {
          savePng(o.outDir + "/crops/" + sc.label + "_full_" + variants[vi].name + ".png", lastOut[vi][0],
                  &error);
        }
      }
    }
  }
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();

  writeResultsCsv(o.outDir + "/results.csv", rows);
  const auto targets = checkTargets(rows, scenarios, defaultTemporal);
  writeJson(o.outDir + "/results.json", o, rows, targets, device, seconds);

  // The table.
  std::cout << "steadyxr-eval: " << scenarios.size() << " scenarios x " << variants.size() << " methods, "
            << o.width << "x" << o.height << " per eye, " << o.frames << " frames at " << o.appHz
            << " Hz (display " << o.displayHz << " Hz), ground truth " << o.gtGrid * o.gtGrid
            << " spp, device " << device << ", " << fmt(seconds, 4) << " s\n";
  std::cout << "MTCD in 8-bit code values (seed 003 Eq. 6); RMSE/SSIM vs ground truth on sRGB-encoded [0,1]; "
               "stereo gap = |stereo diff - ground truth's| x1e3; GPU = filter passes (both eyes)\n";
  std::string current;
  for (const ResultRow& r : rows) {
    if (r.scenario != current) {
      current = r.scenario;
      std::cout << "\n== " << current << "\n"
                << std::left << std::setw(22) << "method" << std::right << std::setw(8) << "MTCD"
                << std::setw(9) << "MTCDdisp" << std::setw(8) << "RMSE" << std::setw(7) << "SSIM"
                << std::setw(9) << "RMSEdisp" << std::setw(8) << "err%" << std::setw(8) << "stGap"
                << std::setw(8) << "GPUms" << std::setw(8) << "costms" << std::setw(8) << "CPUus"
                << "\n";
    }
    std::cout << std::left << std::setw(22) << r.method << std::right << std::fixed << std::setprecision(3)
              << std::setw(8) << r.mtcd << std::setw(9) << r.mtcdDisplay << std::setprecision(4)
              << std::setw(8) << r.rmse << std::setprecision(3) << std::setw(7) << r.ssim
              << std::setprecision(4) << std::setw(9) << r.rmseDisplay << std::setprecision(2) << std::setw(8)
              << r.errPxDisplayPct << std::setprecision(3) << std::setw(8) << 1e3 * r.stereoGap
              << std::setw(8) << r.gpuMs << std::setw(8) << r.costMs << std::setprecision(0) << std::setw(8)
              << r.cpuUs << "\n";
    std::cout.unsetf(std::ios::fixed);
  }
  std::cout << "\nTargets (default = " << core::methodName(*core::applyMethodName("default")) << "):\n";
  for (const TargetCheck& t : targets) {
    std::cout << "  ["
              << (!t.evaluated ? "N/A"
                  : t.met      ? "MET"
                               : "MISSED")
              << "] " << t.name << ": " << t.detail << "\n";
  }
  std::cout << "Outputs: " << o.outDir
            << "/results.csv, results.json, timeseries.csv, warp_errors.csv, crops/*.png\n";
  if (o.validation && ctx->validationMessageCount() > 0) {
    std::cerr << "steadyxr-eval: " << ctx->validationMessageCount()
              << " validation messages, first: " << ctx->validationMessages().front() << "\n";
  }
  return 0;
}

}  // namespace steadyxr::eval
