#include "suite.h"

#include "camera.h"
#include "corpus.h"
#include "crops.h"
#include "image.h"
#include "metrics.h"
#include "oracle.h"
#include "pictures.h"
#include "renderer.h"
#include "results.h"
#include "scenario.h"
#include "scene.h"
#include "targets.h"
#include "variants.h"
#include "warp.h"

#include "steadyxr/core/filter.h"
#include "steadyxr/core/jitter.h"
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

// Running sums of one (scenario, variant).
struct Accum {
  double sqErr = 0, sqN = 0, ssimSum = 0, ssimN = 0;
  double mtcdSum = 0, mtcdN = 0, tempErrSum = 0, tempErrN = 0, mtcdDispSum = 0, mtcdDispN = 0;
  double sqErrDisp = 0, sqDispN = 0, errPxDisp = 0, errPxDispN = 0;
  double stereoSum = 0, stereoN = 0, stereoErrSum = 0, stereoErrN = 0;
  double gpuTemporal = 0, gpuStereo = 0, gpuOther = 0, gpuN = 0;
  double timedWallMs = 0, timedGpuMs = 0;  // medians of the back-to-back timing frames
  double cpuUs = 0, cpuN = 0, renderMs = 0, renderN = 0;
  std::vector<double> frameRmse;  // per frame, both eyes (ghosting per frame)
  std::array<Image, 2> prev, prevDisplay;
};

double safeDiv(double a, double b) {
  return b > 0 ? a / b : 0.0;
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
    s.motionClass = trace ? "trace" : motionClassOf(motion);
    s.pictureClass =
        scene == "imageviewer" || scene == "noisy" ? pictureClass(textureKey(picture)) : "scene:" + scene;
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

// jitterPx: the layer's sub-pixel jitter (core::jitterFov), zero for an unjittered render.
std::array<EyeCamera, 2> eyeCameras(const HeadPose& head, int w, int h,
                                    glm::vec2 jitterPx = glm::vec2(0.0f)) {
  std::array<EyeCamera, 2> cams;
  for (int eye = 0; eye < 2; ++eye) {
    core::Pose p;
    p.orientation = head.orientation;
    p.position = head.position + head.orientation * glm::vec3(eye == 0 ? -kIpdM / 2 : kIpdM / 2, 0.0f, 0.0f);
    const core::Fov fov = core::jitterFov(eyeFov(eye), jitterPx.x, jitterPx.y, uint32_t(w), uint32_t(h));
    cams[eye] = makeEyeCamera(p, fov, w, h, kNearZ, kFarZ);
  }
  return cams;
}

// What every method's output of one frame is scored against.
struct FrameTruth {
  std::array<Image, 2> gt, prevGt;  // prevGt is empty on a case's first frame
  std::array<EyeCamera, 2> cams;    // the unjittered eye cameras (output grid)
  std::array<DepthMap, 2> depth;    // their 1-sample depth (stereo correspondences)
  std::vector<std::array<EyeCamera, 2>> dispCams;
  std::vector<std::array<Image, 2>> dispGt;
};

struct FrameScore {
  double rmse = 0, ssim = 0, mtcd = -1, tempErr = -1, mtcdDisp = -1, rmseDisp = 0, stereoDiff = 0,
         stereoErr = 0;
};

// Scores one frame's output (both eyes) into the method's running sums.
FrameScore scoreFrame(Accum& a, const std::array<Image, 2>& out, const FrameTruth& ft, const Options& o) {
  FrameScore s;
  const double nPix = double(out[0].width) * out[0].height;
  const int ratio = int(ft.dispCams.size());
  double frameSq = 0, frameSqDisp = 0;
  for (int eye = 0; eye < 2; ++eye) {
    const double mse = meanSquaredError(out[eye], ft.gt[eye]);
    frameSq += mse / 2;
    a.sqErr += mse * nPix * 3;
    a.sqN += nPix * 3;
    const double ss = ssim(out[eye], ft.gt[eye]);
    s.ssim += ss / 2;
    a.ssimSum += ss;
    a.ssimN += 1;
    if (!a.prev[eye].empty()) {
      const double m = 255.0 * temporalColorDifference(a.prev[eye], out[eye]);
      s.mtcd = (s.mtcd < 0 ? 0 : s.mtcd) + m / 2;
      a.mtcdSum += m;
      a.mtcdN += 1;
      const double te = 255.0 * temporalErrorVsTruth(a.prev[eye], out[eye], ft.prevGt[eye], ft.gt[eye]);
      s.tempErr = (s.tempErr < 0 ? 0 : s.tempErr) + te / 2;
      a.tempErrSum += te;
      a.tempErrN += 1;
    }
    // Display stage (a): the runtime's rotational timewarp of this frame until the next one.
    for (int k = 0; k < ratio; ++k) {
      const Image shown = k == 0 ? out[eye] : rotationalTimewarp(out[eye], ft.cams[eye], ft.dispCams[k][eye]);
      const double dmse = meanSquaredError(shown, ft.dispGt[k][eye]);
      frameSqDisp += dmse / (2 * ratio);
      a.sqErrDisp += dmse;
      a.sqDispN += 1;
      a.errPxDisp += double(errorPixels(shown, ft.dispGt[k][eye], o.errorThreshold)) / nPix;
      a.errPxDispN += 1;
      if (!a.prevDisplay[eye].empty()) {
        const double m = 255.0 * temporalColorDifference(a.prevDisplay[eye], shown);
        s.mtcdDisp = (s.mtcdDisp < 0 ? 0 : s.mtcdDisp) + m / (2 * ratio);
        a.mtcdDispSum += m;
        a.mtcdDispN += 1;
      }
      a.prevDisplay[eye] = shown;
    }
  }
  s.rmse = std::sqrt(frameSq);
  s.rmseDisp = std::sqrt(frameSqDisp);
  a.frameRmse.push_back(s.rmse);
  s.stereoDiff =
      stereoDifference(out[0], ft.depth[0], ft.cams[0], out[1], ft.depth[1], ft.cams[1]).meanSquared;
  a.stereoSum += s.stereoDiff;
  a.stereoN += 1;
  s.stereoErr = 255.0 * stereoErrorPerPixel(out[0], out[1], ft.gt[0], ft.gt[1], ft.depth[0], ft.cams[0],
                                            ft.depth[1], ft.cams[1]);
  a.stereoErrSum += s.stereoErr;
  a.stereoErrN += 1;
  a.prev = out;
  return s;
}

// The methods shown in crops, in this order, where the run has them.
const std::vector<std::string> kCropMethods = {
    "none", "fxaa", "msaa4", "taa", "taa+jitter", "hmtaa", "vtaa", "default", "default+jitter", "oracle"};
// The animated comparison's columns after the ground truth.
const std::vector<std::string> kAnimationMethods = {"none", "taa+jitter", "default"};

int indexOf(const std::vector<Variant>& variants, const std::string& name) {
  for (size_t i = 0; i < variants.size(); ++i) {
    if (variants[i].name == name) return int(i);
  }
  return -1;
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
  const std::vector<std::string> specs = !o.methods.empty() ? o.methods
                                         : o.corpus         ? corpusMethods()
                                                            : defaultMethods(o.sweeps && !o.quick);
  for (const std::string& spec : specs) {
    Variant v;
    if (!parseVariant(spec, &v, &error)) {
      std::cerr << "steadyxr-eval: " << error << "\n";
      return 2;
    }
    variants.push_back(std::move(v));
  }
  // Jittered methods run after the others each frame (their render replaces the 1-sample one in
  // the eye targets), the CPU oracle last.
  std::stable_partition(variants.begin(), variants.end(),
                        [](const Variant& v) { return !v.jitter && !v.oracle; });
  std::stable_partition(variants.begin(), variants.end(), [](const Variant& v) { return !v.oracle; });
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
      textures.images.push_back(isProceduralPicture(name)
                                    ? proceduralPicture(name, o.height)
                                    : loadTextureOrFallback(name, o.picturesDir, &warning));
      textures.names.push_back(textureKey(name));
      if (!warning.empty()) std::cerr << "steadyxr-eval: " << warning << "\n";
    }
  }
  RenderOptions renderOptions;
  renderOptions.srgb = !o.unorm;
  renderOptions.mipmaps = o.mipmaps;
  auto renderer = SceneRenderer::create(*ctx, o.width, o.height, textures.images, renderOptions, &error);
  if (!renderer) {
    std::cerr << "steadyxr-eval: renderer: " << error << "\n";
    return 1;
  }
  std::erase_if(variants, [&](const Variant& v) {
    if (renderer->supportsSamples(v.source)) return false;
    std::cerr << "steadyxr-eval: skipping '" << v.name << "': " << v.source << "x MSAA not supported by "
              << device << "\n";
    return true;
  });
  bool anyJitter = false;
  for (Variant& v : variants) {
    anyJitter = anyJitter || v.jitter;
    if (v.oracle) continue;
    v.filter = core::Filter::create(*ctx, v.params, &error);
    if (!v.filter) {
      std::cerr << "steadyxr-eval: filter '" << v.name << "': " << error << "\n";
      return 1;
    }
  }
  const std::string defaultTemporal = std::string(core::toString(core::kDefaultTemporalMethod));
  const int noneIndex = indexOf(variants, "none"), defaultIndex = indexOf(variants, "default");
  // The animated comparison: the case asked for, else the zone plate under fixation (shimmer shows
  // best on it), else the first case; none in a corpus run unless asked for.
  std::string animateLabel = o.animate;
  if (animateLabel.empty() && !o.corpus) {
    animateLabel = scenarios.front().label;
    for (const Scenario& s : scenarios) {
      if (s.picture == "zoneplate" && s.motionClass == "still") {
        animateLabel = s.label;
        break;
      }
    }
  }

  std::vector<ResultRow> rows;
  std::ofstream series(o.outDir + "/timeseries.csv");
  series << "scenario,method,frame,t_s,head_speed_deg_s,object_speed_m_s,mtcd,temporal_error,rmse,ssim,"
            "stereo_diff,"
            "stereo_diff_gt,stereo_error,mtcd_display,rmse_display\n";
  std::ofstream warpCsv(o.outDir + "/warp_errors.csv");
  warpCsv << "scenario,frame,step,extrapolation_ms,head_speed_deg_s,object_speed_m_s,mode,error_pixels,"
             "error_fraction\n";

  const double dt = 1.0 / o.appHz;
  const int ratio = std::max(1, int(std::lround(o.displayHz / o.appHz)));
  Progress progress(o.progress, int(scenarios.size()) * o.frames);
  int framesDone = 0;
  const size_t nPix = size_t(o.width) * o.height;
  Oracle oracle(!o.unorm);
  const CropWindow cropWindow = centreCrop(o.width, o.height);
  // The animation's crop: an eighth of the image (a 40-frame GIF of four fifth-crops is 2 MB).
  CropWindow animationWindow = cropWindow;
  animationWindow.width = std::max(8, o.width / 8);
  animationWindow.height = std::max(8, o.height / 8);
  animationWindow.x0 = o.width / 2 - animationWindow.width / 2;
  animationWindow.y0 = o.height / 2 - animationWindow.height / 2;

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
    const double start = sc.startSec >= 0.0 ? sc.startSec : o.startSec;
    const double lastSec =
        start - sc.leadSec + (o.frames - 1) * dt + std::max(o.warpSteps, ratio) / o.displayHz;
    if (stream->validUntilSec() < lastSec) {
      // A trace shorter than the run is an error, not a silently held last pose.
      std::cerr << "steadyxr-eval: motion '" << sc.motion << "' ends at " << stream->validUntilSec()
                << " s, the run needs it until " << lastSec << " s (fewer --frames or an earlier --start)\n";
      return 2;
    }
    auto headAt = [&](double t) {
      const imu::MotionState m = stream->at(std::max(0.0, t));
      return HeadPose{glm::normalize(m.orientation), m.position + scene.headOffset(t)};
    };
    std::vector<Accum> acc(variants.size());
    for (Variant& v : variants) {
      if (v.filter) v.filter->reset();
    }
    oracle.reset();
    const bool oracleHere = !scene.hasMovingObject;
    double gtStereoSum = 0, gtStereoN = 0;
    std::vector<double> headSpeeds;
    FrameTruth ft;
    std::vector<std::array<Image, 2>> lastOut(variants.size()), worstOut(variants.size());
    std::array<Image, 2> worstGt;
    double worstRatio = -1.0;
    int worstFrame = -1;
    std::vector<std::optional<core::StereoFrame>> lastFrame(variants.size());
    auto active = [&](const Variant& v) { return (!v.sweep || sc.sweeps) && (!v.oracle || oracleHere); };

    for (int f = 0; f < o.frames; ++f) {
      const double t = start - sc.leadSec + f * dt;
      const HeadPose head = headAt(t);
      // The head's angular speed at the frame (the stream's angular velocity: a trace's wx,wy,wz,
      // the IMU path's gyro), not a difference of two frames' poses.
      const float headSpeed = float(stream->headSpeedDegPerSec(std::max(0.0, t)));
      headSpeeds.push_back(headSpeed);
      const auto cams = eyeCameras(head, o.width, o.height);
      // The layer's jitter of this frame (xrLocateViews call f), as `jitter = 1` injects it.
      const glm::vec2 jitter = core::haltonJitterPx(uint32_t(f));
      const float objSpeed = scene.objectSpeed(t);

      // The app's images (1 sample), MSAA baselines and the ground truth, both eyes.
      std::array<RenderedView, 2> base;
      std::array<std::array<Image, 2>, 2> msaa;
      double baseMs = 0;
      std::array<double, 2> msaaMs{0, 0};
      bool needMsaa[2] = {false, false};
      for (const Variant& v : variants) {
        if (v.source == 2) needMsaa[0] = true;
        if (v.source == 4) needMsaa[1] = true;
      }
      ft.prevGt = ft.gt;
      auto drawsOf = [&](int eye) {
        DrawList draws = scene.drawsAt(t);
        draws.noiseSeed = uint32_t(f * 2 + eye + 1);
        if (o.noise > 0.0f) draws.noiseAmplitude = o.noise;
        return draws;
      };
      for (int eye = 0; eye < 2; ++eye) {
        const DrawList draws = drawsOf(eye);
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
        if (!renderer->renderGroundTruth(cams[eye], draws, o.gtGrid, &ft.gt[eye], &error)) {
          std::cerr << "steadyxr-eval: ground truth: " << error << "\n";
          return 1;
        }
        ft.depth[eye] = base[eye].depth;
      }
      ft.cams = cams;
      const StereoDifference gtSd =
          stereoDifference(ft.gt[0], base[0].depth, cams[0], ft.gt[1], base[1].depth, cams[1]);
      gtStereoSum += gtSd.meanSquared;
      gtStereoN += 1;

      // Display stage references: head poses and ground truth at the display times in between.
      ft.dispCams.assign(ratio, cams);
      ft.dispGt.assign(ratio, ft.gt);
      for (int k = 1; k < ratio; ++k) {
        const double td = t + k / o.displayHz;
        ft.dispCams[k] = eyeCameras(headAt(td), o.width, o.height);
        for (int eye = 0; eye < 2; ++eye) {
          if (!renderer->renderGroundTruth(ft.dispCams[k][eye], scene.drawsAt(td), o.gtGrid,
                                           &ft.dispGt[k][eye], &error)) {
            std::cerr << "steadyxr-eval: ground truth: " << error << "\n";
            return 1;
          }
        }
      }

      std::array<RenderedView, 2> jittered;
      bool jitterRendered = false;
      std::array<EyeCamera, 2> jitterCams = eyeCameras(head, o.width, o.height, jitter);
      std::vector<std::array<Image, 2>> frameOut(variants.size());
      for (size_t vi = 0; vi < variants.size(); ++vi) {
        Variant& v = variants[vi];
        Accum& a = acc[vi];
        if (!active(v)) continue;
        std::array<Image, 2> out;
        if ((v.jitter || (v.oracle && anyJitter)) && !jitterRendered) {
          // The jittered app frame: what the app renders with the fov the layer handed it.
          for (int eye = 0; eye < 2; ++eye) {
            if (!renderer->renderBase(eye, jitterCams[eye], drawsOf(eye), &jittered[eye], nullptr, &error)) {
              std::cerr << "steadyxr-eval: render: " << error << "\n";
              return 1;
            }
          }
          jitterRendered = true;
        }
        if (v.oracle) {
          const auto& src = anyJitter ? jittered : base;
          const auto& srcCams = anyJitter ? jitterCams : cams;
          for (int eye = 0; eye < 2; ++eye) {
            out[eye] =
                oracle.step(eye, src[eye].color, src[eye].depth, srcCams[eye], base[eye].depth, cams[eye]);
          }
        } else {
          core::StereoFrame frame;
          for (int eye = 0; eye < 2; ++eye) {
            core::ViewFrame& view = frame.views[eye];
            view.color = v.source == 1 ? renderer->baseColor(eye) : renderer->msaaColor(v.source, eye);
            if (sc.depthGiven) view.depth = renderer->baseDepth(eye, kNearZ, kFarZ);
            view.pose = cams[eye].pose;
            view.fov = cams[eye].fov;  // the unjittered fov, as the layer submits after un-jittering
            if (v.jitter) view.jitterPx = jitter;
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
            a.renderMs += v.source == 1 ? baseMs : msaaMs[v.source == 2 ? 0 : 1];
            a.renderN += 1;
          }
          if (auto tm = v.filter->lastTimings(); tm && warm) {
            a.gpuTemporal += tm->temporalMs;
            a.gpuStereo += tm->stereoMs;
            a.gpuOther += tm->otherMs;
            a.gpuN += 1;
          }
          for (int eye = 0; eye < 2; ++eye) {
            if (!renderer->readOutput(eye, &out[eye], &error)) {
              std::cerr << "steadyxr-eval: readback: " << error << "\n";
              return 1;
            }
          }
        }
        const FrameScore s = scoreFrame(a, out, ft, o);
        auto opt = [](double x) { return x < 0 ? std::string() : fmt(x, 6); };
        series << csvEscape(sc.label) << ',' << v.name << ',' << f << ',' << fmt(t, 6) << ','
               << fmt(headSpeed, 5) << ',' << fmt(objSpeed, 5) << ',' << opt(s.mtcd) << ',' << opt(s.tempErr)
               << ',' << fmt(s.rmse, 6) << ',' << fmt(s.ssim, 6) << ',' << fmt(s.stereoDiff, 6) << ','
               << fmt(gtSd.meanSquared, 6) << ',' << fmt(s.stereoErr, 6) << ',' << opt(s.mtcdDisp) << ','
               << fmt(s.rmseDisp, 6) << '\n';
        frameOut[vi] = std::move(out);
      }
      // The default's worst frame against none's so far: keep every method's images of it (crops).
      if (noneIndex >= 0 && defaultIndex >= 0 && !acc[defaultIndex].frameRmse.empty()) {
        const double r = safeDiv(acc[defaultIndex].frameRmse.back(), acc[noneIndex].frameRmse.back());
        if (r > worstRatio) {
          worstRatio = r;
          worstFrame = f;
          worstOut = frameOut;
          worstGt = ft.gt;
        }
      }
      if (sc.label == animateLabel) {
        std::vector<Tile> tiles = {{"gt", ft.gt[0]}};
        for (const std::string& m : kAnimationMethods) {
          const int i = indexOf(variants, m);
          if (i >= 0 && !frameOut[i][0].empty()) tiles.push_back({m, frameOut[i][0]});
        }
        std::filesystem::create_directories(o.outDir + "/anim/" + sc.label);
        char name[32];
        std::snprintf(name, sizeof(name), "/frame_%03d.png", f);
        writeAnimationFrame(o.outDir + "/anim/" + sc.label + name, tiles, animationWindow, &error);
      }
      for (size_t vi = 0; vi < variants.size(); ++vi) {
        if (!frameOut[vi][0].empty()) lastOut[vi] = std::move(frameOut[vi]);
      }

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
      if (!active(v) || !lastFrame[vi] || !v.filter) continue;
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
      acc[vi].timedWallMs = percentile(wall, 0.5);
      acc[vi].timedGpuMs = percentile(gpu, 0.5);
    }

    // Rows of this scenario.
    const double gtStereo = safeDiv(gtStereoSum, gtStereoN);
    // Motion changes: the preset's own change times (the first frame at or after each), else, for
    // a trace, detected from the head speed.
    std::vector<int> changes;
    if (sc.trace) {
      changes = detectMotionChanges(headSpeeds, kMotionChangeDegPerSec);
    } else {
      for (double tc : stream->motionChangeTimes()) {
        const int k = int(std::ceil((tc - (start - sc.leadSec)) / dt - 1e-9));
        if (k >= 0 && k < o.frames && (changes.empty() || changes.back() != k)) changes.push_back(k);
      }
    }
    const double p95 = percentile(headSpeeds, 0.95);
    for (size_t vi = 0; vi < variants.size(); ++vi) {
      const Variant& v = variants[vi];
      const Accum& a = acc[vi];
      if (!active(v)) continue;
      ResultRow r;
      r.scenario = sc.label;
      r.scene = sc.scene;
      r.motion = sc.trace ? std::filesystem::path(sc.motion).stem().string() : sc.motion;
      r.picture = (sc.scene == "imageviewer" || sc.scene == "noisy") ? textureKey(sc.picture) : "";
      r.motionClass = sc.motionClass;
      r.pictureClass = sc.pictureClass;
      r.method = v.name;
      r.filterMethod = v.oracle ? "oracle" : core::methodName(v.params);
      r.sweep = v.sweep;
      r.stereo = v.params.stereo;
      r.jitter = v.jitter;
      r.depthGiven = sc.depthGiven;
      r.source = v.source;
      r.mtcd = safeDiv(a.mtcdSum, a.mtcdN);
      r.temporalError = safeDiv(a.tempErrSum, a.tempErrN);
      r.mtcdDisplay = safeDiv(a.mtcdDispSum, a.mtcdDispN);
      r.rmse = std::sqrt(safeDiv(a.sqErr, a.sqN));
      r.ssim = safeDiv(a.ssimSum, a.ssimN);
      r.rmseDisplay = std::sqrt(safeDiv(a.sqErrDisp, a.sqDispN));
      r.errPxDisplayPct = 100.0 * safeDiv(a.errPxDisp, a.errPxDispN);
      r.stereoError = safeDiv(a.stereoErrSum, a.stereoErrN);
      r.stereoDiff = safeDiv(a.stereoSum, a.stereoN);
      r.stereoDiffGt = gtStereo;
      r.stereoGap = std::fabs(r.stereoDiff - gtStereo);
      if (noneIndex >= 0) {
        const Ghosting g = ghostingPerFrame(a.frameRmse, acc[noneIndex].frameRmse, changes);
        r.ghostWorstRatio = g.worstRatio;
        r.ghostWorstFrame = g.worstFrame;
        r.recoveryFrames = g.recoveryFrames;
        r.recovered = g.recovered;
      }
      r.motionChanges = int(changes.size());
      r.headSpeedP95 = p95;
      r.lowSpeed = p95 < kLowSpeedDegPerSec;
      r.staticScene = !scene.hasMovingObject;
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
      if (r.scenario == sc.label && r.source == 1 && r.renderMs > 0) baseRender = r.renderMs;
    }
    for (ResultRow& r : rows) {
      if (r.scenario == sc.label) r.costMs = r.gpuMs + std::max(0.0, r.renderMs - baseRender);
    }

    // Labelled, magnified crops (seed 003 Fig. 4) at the last frame and at the default's worst.
    auto tilesOf = [&](const std::vector<std::array<Image, 2>>& images) {
      std::vector<Tile> tiles;
      for (const std::string& m : kCropMethods) {
        const int i = indexOf(variants, m);
        if (i >= 0 && !images[i][0].empty()) tiles.push_back({m, images[i][0]});
      }
      return tiles;
    };
    writeCropStrip(o.outDir + "/crops/" + sc.label + ".png", tilesOf(lastOut), ft.gt[0], cropWindow,
                   sc.label + " last frame " + std::to_string(o.frames - 1) + ", row 2: difference x4",
                   &error);
    if (worstFrame >= 0) {
      writeCropStrip(o.outDir + "/crops/" + sc.label + "_worst.png", tilesOf(worstOut), worstGt[0],
                     cropWindow,
                     sc.label + " frame " + std::to_string(worstFrame) +
                         " (default's worst: " + fmt(worstRatio, 3) + "x none), row 2: difference x4",
                     &error);
    }
  }
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();

  writeResultsCsv(o.outDir + "/results.csv", rows);
  const auto targets = checkTargets(rows, defaultTemporal);
  writeResultsJson(o.outDir + "/results.json", o, rows, targets, device, seconds);
  if (o.corpus) writeCorpusCsv(o.outDir + "/corpus.csv", rows);

  std::cout << "steadyxr-eval: " << scenarios.size() << " cases x " << variants.size() << " methods, "
            << o.width << "x" << o.height << " per eye, " << o.frames << " frames at " << o.appHz
            << " Hz (display " << o.displayHz << " Hz), ground truth " << o.gtGrid * o.gtGrid << " spp, "
            << (o.unorm ? "UNORM" : "sRGB") << " eye images, "
            << (o.mipmaps ? "trilinear mipmaps" : "no mipmaps") << ", device " << device << ", "
            << fmt(seconds, 4) << " s\n";
  std::cout
      << "MTCD (seed 003 Eq. 6), TempErr (temporal error vs ground truth) and StErr (per-pixel stereo error) "
         "in 8-bit code values; RMSE/SSIM vs ground truth on display-encoded [0,1]; worst/n = worst frame's "
         "RMSE / none's there; recov = most frames after a motion change until RMSE <= none's (+: not by the "
         "end); GPU = filter passes (both eyes)\n";
  printResults(rows, targets, !o.corpus);
  if (o.corpus) printCorpusTable(rows, std::cout);
  std::cout << "Outputs: " << o.outDir
            << "/results.csv, results.json, timeseries.csv, warp_errors.csv, crops/*.png"
            << (o.corpus ? ", corpus.csv" : "")
            << (animateLabel.empty() ? "" : ", anim/" + animateLabel + "/") << "\n";
  if (o.validation && ctx->validationMessageCount() > 0) {
    std::cerr << "steadyxr-eval: " << ctx->validationMessageCount()
              << " validation messages, first: " << ctx->validationMessages().front() << "\n";
  }
  return 0;
}

}  // namespace steadyxr::eval
