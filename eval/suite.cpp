// runSuite: runs every scenario x method frame by frame (render both eyes at the head pose ->
// filter core -> display stage -> metrics), then writes the result files, crops and tables.
#include "suite.h"

#include "camera.h"
#include "case_rows.h"
#include "corpus.h"
#include "cost_timing.h"
#include "crops.h"
#include "eye_rig.h"
#include "frame_clock.h"
#include "frame_score.h"
#include "head_locked_detector.h"
#include "image.h"
#include "locomotion.h"
#include "metrics.h"
#include "oracle.h"
#include "progress.h"
#include "renderer.h"
#include "resolved_edges.h"
#include "results.h"
#include "scenario_list.h"
#include "scene.h"
#include "scene_hud.h"
#include "targets.h"
#include "variants.h"
#include "warp_study.h"

#include "steadyxr/core/filter.h"
#include "steadyxr/core/jitter.h"
#include "steadyxr/core/params.h"
#include "steadyxr/core/vulkan_context.h"
#include "steadyxr/imu/motion.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>

#include <glm/glm.hpp>

namespace steadyxr::eval {

namespace {

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

// --write-frames: frame f's left-eye truth and each method's output (those that ran) as PNGs in dir.
bool writeFrames(const std::string& dir, int f, const Image& truth, const std::vector<Variant>& variants,
                 const std::vector<std::array<Image, 2>>& outputs, std::string* error) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  std::string suffix = "_";  // appended: GCC 12 at -O3 warns (-Wrestrict) on "_" + std::string&&
  suffix += std::to_string(f);
  suffix += ".png";
  if (ec || !savePng(dir + "/gt" + suffix, truth, error)) {
    if (ec) *error = dir + ": " + ec.message();
    return false;
  }
  for (size_t vi = 0; vi < variants.size(); ++vi) {
    if (!outputs[vi][0].empty() && !savePng(dir + "/" + variants[vi].name + suffix, outputs[vi][0], error))
      return false;
  }
  return true;
}

}  // namespace

std::unique_ptr<core::VulkanContext> createEvalContext(const Options& o, std::string* error) {
  core::OwnedContextOptions co;
  co.enableValidation = o.validation;
  co.applicationName = "steadyxr-eval";
  return core::VulkanContext::createOwned(co, error);
}

int runSuite(const Options& o) {
  const auto wallStart = std::chrono::steady_clock::now();
  std::string error;
  std::vector<Scenario> scenarios;
  TextureSet textures;
  if (!loadCases(o, &scenarios, &textures, &error)) {
    std::cerr << "steadyxr-eval: " << error << "\n";
    return 2;
  }
  // Created first so that it outlives every filter and renderer below.
  auto ctx = createEvalContext(o, &error);
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

  RenderOptions renderOptions;
  renderOptions.srgb = !o.unorm;
  renderOptions.mipmaps = o.mipmaps;
  auto renderer = SceneRenderer::create(*ctx, o.width, o.height, textures.images, renderOptions, &error);
  if (!renderer) {
    std::cerr << "steadyxr-eval: renderer: " << error << "\n";
    return 1;
  }
  if (!renderer->supportsSamples(o.appMsaa)) {
    std::cerr << "steadyxr-eval: --app-msaa " << o.appMsaa << ": not supported by " << device << "\n";
    return 1;
  }
  std::erase_if(variants, [&](const Variant& v) {
    if (renderer->supportsSamples(v.source)) return false;
    std::cerr << "steadyxr-eval: skipping '" << v.name << "': " << v.source << "x MSAA not supported by "
              << device << "\n";
    return true;
  });
  // A 1-sample variant reads the app's own image, which has the app's samples (--app-msaa): what it
  // reads, its render time and its results row's samples all follow from its source.
  for (Variant& v : variants) {
    if (v.source == 1) v.source = o.appMsaa;
  }
  for (Variant& v : variants) {
    if (v.oracle) continue;
    if (o.ppd > 0.0) {
      // The layer's assumed distances stand for a real scene's; under --ppd every scene's depths
      // are 1/s times its own (scene.h, makeScene), so are these: the no-depth stereo disparity
      // and its nearest-depth spread then come out in the pixels they have without --ppd.
      const float depthScale = float(1.0 / ppdTangentScale(o.ppd, o.width));
      v.params.stereoFarDistanceM *= depthScale;
      v.params.steadyNearestDepthM *= depthScale;
    }
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
  // Head-locked content's own pixels (scene `hud`): RMSE per frame on the overlay mask (scene_hud.h).
  std::ofstream overlayCsv;
  // An MSAA app (--app-msaa): RMSE per frame on its resolved edges, the ring beside them and the rest.
  std::ofstream edgesCsv;
  if (o.appMsaa > 1) {
    edgesCsv.open(o.outDir + "/resolved_edges.csv");
    edgesCsv << kResolvedEdgesCsvHeader << '\n';
  }
  std::ofstream autoHudCsv;    // round 41's study: when the detector decided, and its epochs
  std::ofstream hudSwitchCsv;  // round 42: when the filter's own head-locked switch decided
  std::ofstream warpCsv(o.outDir + "/warp_errors.csv");
  warpCsv << "scenario,frame,step,extrapolation_ms,head_speed_deg_s,object_speed_m_s,mode,error_pixels,"
             "error_fraction\n";

  const double dt = 1.0 / o.appHz;
  const int ratio = std::max(1, int(std::lround(o.displayHz / o.appHz)));
  Progress progress(o.progress, int(scenarios.size()) * o.frames);
  int framesDone = 0;
  // One oracle per input: `oracle` takes the unjittered frames the default filters, `oracle+jitter`
  // the layer's jittered ones, whichever other methods the run has (its figures must not depend
  // on the method list).
  std::array<Oracle, 2> oracles{Oracle(!o.unorm), Oracle(!o.unorm)};
  const CropWindow cropWindow = centreCrop(o.width, o.height);
  // The animation's crop: an eighth of the image (a 40-frame GIF of four fifth-crops is 2 MB).
  CropWindow animationWindow = cropWindow;
  animationWindow.width = std::max(8, o.width / 8);
  animationWindow.height = std::max(8, o.height / 8);
  animationWindow.x0 = o.width / 2 - animationWindow.width / 2;
  animationWindow.y0 = o.height / 2 - animationWindow.height / 2;

  for (const Scenario& sc : scenarios) {
    CaseMotion motion;
    if (!loadMotion(sc, o, &motion, &error)) {
      std::cerr << "steadyxr-eval: " << error << "\n";
      return 2;
    }
    const std::unique_ptr<imu::MotionStream>& stream = motion.stream;
    const double start = motion.startSec, firstFrameSec = motion.firstFrameSec;  // on the stream's clock
    const FrameClock clock(o.frames, firstFrameSec, dt, o.dropFrames, o.seed);
    Scene scene;
    // --ppd stretches a scene in metres about the first frame's head (scene.h, makeScene).
    // (Asked only under --ppd: without it the stream sees the calls it always saw.)
    HeadPose ppdStartHead;
    if (o.ppd > 0.0) {
      const imu::MotionState firstMotion = stream->at(std::max(0.0, firstFrameSec));
      ppdStartHead = HeadPose{glm::normalize(firstMotion.orientation), firstMotion.position};
    }
    if (!makeScene(sc.scene, sc.picture, textures, ppdTangentScale(o.ppd, o.width), ppdStartHead, &scene,
                   &error)) {
      std::cerr << "steadyxr-eval: " << error << "\n";
      return 2;
    }
    const double lastSec = clock.lastSec() + std::max(o.warpSteps, ratio) / o.displayHz;
    if (stream->validUntilSec() < lastSec) {
      // A trace shorter than the run is an error, not a silently held last pose.
      std::cerr << "steadyxr-eval: motion '" << sc.motion << "' ends at " << stream->validUntilSec()
                << " s, the run needs it until " << lastSec << " s (fewer --frames or an earlier --start)\n";
      return 2;
    }
    // The tracked head (what the app submits and the layer is told), and the pose the app renders
    // from: the same, unless --locomotion moves the app's rig on top (locomotion.h).
    auto trackedAt = [&](double t) {
      const imu::MotionState m = stream->at(std::max(0.0, t));
      return HeadPose{glm::normalize(m.orientation), m.position + scene.headOffset(t)};
    };
    const RigSchedule rig{double(clock.periodOf(o.frames - 1)) * dt, trackedAt(firstFrameSec),
                          1.0 / ppdTangentScale(o.ppd, o.width)};
    auto headAt = [&](double t) { return rigPose(o.locomotion, rig, trackedAt(t), t - firstFrameSec); };
    std::vector<Accum> acc(variants.size());
    // Uniform noise of amplitude F has the variance F^2 / 3 per channel (eval/shaders/scene.frag).
    const float noiseAmplitude =
        o.noise > 0.0f ? o.noise : scene.drawsAt(start, headAt(start)).noiseAmplitude;
    for (Variant& v : variants) {
      if (v.filter && v.autoHud) v.filter->setParams(v.params);  // the last case may have switched it
      if (v.filter && v.noiseOracle > 0.0f) {
        core::Params told = v.params;
        told.steadyNoiseVariance = v.noiseOracle * noiseAmplitude * noiseAmplitude / 3.0f;
        v.filter->setParams(told);
      }
      if (v.filter) v.filter->reset();
    }
    for (Oracle& oracle : oracles) oracle.reset();
    const bool oracleHere = !scene.hasMovingObject;
    double gtStereoSum = 0, gtStereoN = 0;
    double truth8TempErrSum = 0, truth8TempErrN = 0;  // the 8-bit floor of the temporal error (metrics.h)
    std::vector<double> headSpeeds;
    FrameTruth ft;
    std::vector<std::array<Image, 2>> lastOut(variants.size()), worstOut(variants.size());
    std::array<Image, 2> worstGt;
    double worstRatio = -1.0;
    int worstFrame = -1;
    std::vector<std::optional<core::StereoFrame>> lastFrame(variants.size());
    auto active = [&](const Variant& v) { return (!v.sweep || sc.sweeps) && (!v.oracle || oracleHere); };

    HeadLockedDetector headLocked;
    std::vector<int> hudSwitchedAfter(variants.size(), -1);  // round 42: the frame after which it switched
    const bool detects =
        std::any_of(variants.begin(), variants.end(), [](const Variant& v) { return v.autoHud; });
    for (int f = 0; f < o.frames; ++f) {
      const double t = clock.timeOf(f);
      const HeadPose head = headAt(t);
      // The head's angular speed at the frame (the stream's angular velocity: a trace's wx,wy,wz,
      // the IMU path's gyro), not a difference of two frames' poses.
      const float headSpeed = float(stream->headSpeedDegPerSec(std::max(0.0, t)));
      headSpeeds.push_back(headSpeed);
      const auto cams = eyeCameras(head, o.width, o.height, o.eyeRig());
      const auto trackedCams = eyeCameras(trackedAt(t), o.width, o.height, o.eyeRig());
      // The layer's jitter of this frame (xrLocateViews call f), as `jitter = 1` injects it.
      const glm::vec2 jitter = core::haltonJitterPx(uint32_t(f));
      const float objSpeed = scene.objectSpeed(t);

      // The app's images (1 sample), MSAA baselines and the ground truth, both eyes.
      std::array<RenderedView, 2> base;
      std::array<Image, 2> oneSampleColor;  // --app-msaa: the same frame from 1 sample
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
        DrawList draws = scene.drawsAt(t, head);
        draws.noiseSeed = uint32_t(f * 2 + eye + 1);
        if (o.noise > 0.0f) draws.noiseAmplitude = o.noise;
        return draws;
      };
      for (int eye = 0; eye < 2; ++eye) {
        const DrawList draws = drawsOf(eye);
        double ms = 0;
        if (!renderer->renderApp(o.appMsaa, eye, cams[eye], draws, &base[eye], &ms, &error,
                                 &oneSampleColor[eye])) {
          std::cerr << "steadyxr-eval: render: " << error << "\n";
          return 1;
        }
        baseMs += ms;
        for (int i = 0; i < 2; ++i) {
          if (!needMsaa[i]) continue;
          if ((i == 0 ? 2 : 4) == o.appMsaa) {  // the app's own render: its time, no second render
            msaaMs[i] += ms;
            continue;
          }
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
      // Round 41's study: the layer would read its probe's evidence after the frame, so a decision in
      // frame f switches the profile from frame f + 1 on.
      const bool switchToHud = detects && headLocked.decided() && headLocked.decidedFrame() == f - 1;
      if (detects) headLocked.observe(f, {&base[0].color, &base[1].color}, trackedCams);
      for (Variant& v : variants)
        if (switchToHud && v.autoHud && v.filter) v.filter->setParams(core::withHudProfile(v.params));
      const StereoDifference gtSd =
          stereoDifference(ft.gt[0], base[0].depth, cams[0], ft.gt[1], base[1].depth, cams[1]);
      gtStereoSum += gtSd.meanSquared;
      gtStereoN += 1;
      for (int eye = 0; eye < 2 && !ft.prevGt[eye].empty(); ++eye) {
        truth8TempErrSum += 255.0 * temporalErrorVsTruth(roundTo8Bit(ft.prevGt[eye]), roundTo8Bit(ft.gt[eye]),
                                                         ft.prevGt[eye], ft.gt[eye]);
        truth8TempErrN += 1;
      }

      // Display stage references: head poses and ground truth at the display times in between.
      ft.dispCams.assign(ratio, cams);
      ft.dispGt.assign(ratio, ft.gt);
      for (int k = 1; k < ratio; ++k) {
        const double td = t + k / o.displayHz;
        ft.dispCams[k] = eyeCameras(headAt(td), o.width, o.height, o.eyeRig());
        for (int eye = 0; eye < 2; ++eye) {
          if (!renderer->renderGroundTruth(ft.dispCams[k][eye], scene.drawsAt(td, headAt(td)), o.gtGrid,
                                           &ft.dispGt[k][eye], &error)) {
            std::cerr << "steadyxr-eval: ground truth: " << error << "\n";
            return 1;
          }
        }
      }

      // The overlay's pixels in this frame's 1-sample render (head-locked: the same every frame).
      OverlayMasks overlay;
      if (!scene.headLocked.empty()) {
        if (!overlayCsv.is_open()) {
          overlayCsv.open(o.outDir + "/overlay.csv");
          overlayCsv << kOverlayCsvHeader << '\n';
        }
        overlay = overlayMasks({&base[0].depth, &base[1].depth}, cams, ppdTangentScale(o.ppd, o.width));
      }
      const ResolvedEdgeMasks edges = o.appMsaa > 1
                                          ? resolvedEdgeMasks(oneSampleColor, {base[0].color, base[1].color})
                                          : ResolvedEdgeMasks{};
      std::array<RenderedView, 2> jittered;
      bool jitterRendered = false;
      std::array<EyeCamera, 2> jitterCams = eyeCameras(head, o.width, o.height, o.eyeRig(), jitter);
      std::vector<std::array<Image, 2>> frameOut(variants.size());
      for (size_t vi = 0; vi < variants.size(); ++vi) {
        Variant& v = variants[vi];
        Accum& a = acc[vi];
        if (!active(v)) continue;
        std::array<Image, 2> out;
        if (v.jitter && !jitterRendered) {
          // The jittered app frame: what the app renders with the fov the layer handed it.
          for (int eye = 0; eye < 2; ++eye) {
            if (!renderer->renderApp(o.appMsaa, eye, jitterCams[eye], drawsOf(eye), &jittered[eye], nullptr,
                                     &error)) {
              std::cerr << "steadyxr-eval: render: " << error << "\n";
              return 1;
            }
          }
          jitterRendered = true;
        }
        if (v.oracle) {
          const auto& src = v.jitter ? jittered : base;
          const auto& srcCams = v.jitter ? jitterCams : cams;
          for (int eye = 0; eye < 2; ++eye) {
            out[eye] = oracles[v.jitter].step(eye, src[eye].color, src[eye].depth, srcCams[eye],
                                              base[eye].depth, cams[eye]);
          }
        } else {
          core::StereoFrame frame;
          for (int eye = 0; eye < 2; ++eye) {
            core::ViewFrame& view = frame.views[eye];
            view.color = renderer->colorOf(v.source, eye);
            if (sc.depthGiven) view.depth = renderer->baseDepth(eye, cams[eye].nearZ, cams[eye].farZ);
            view.pose = trackedCams[eye].pose;  // the tracked head's, without the app's rig
            view.fov = cams[eye].fov;           // the unjittered fov, as the layer submits after un-jittering
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
          if (const auto e = v.filter->headLockedEvidence(); hudSwitchedAfter[vi] < 0 && e && e->decidedFrame)
            hudSwitchedAfter[vi] = f;
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
        if (!scene.headLocked.empty())
          overlayCsv << csvEscape(sc.label) << ',' << v.name << ',' << f << ','
                     << overlayCsvRow(out, ft.gt, overlay) << '\n';
        if (edgesCsv.is_open())
          edgesCsv << csvEscape(sc.label) << ',' << v.name << ',' << f << ','
                   << resolvedEdgesCsvRow(out, ft.gt, edges) << '\n';
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
      if (o.writeFramesEvery > 0 && f % o.writeFramesEvery == 0 &&
          !writeFrames(o.outDir + "/frames/" + sc.label, f, ft.gt[0], variants, frameOut, &error)) {
        std::cerr << "steadyxr-eval: --write-frames: " << error << "\n";
        return 1;
      }
      for (size_t vi = 0; vi < variants.size(); ++vi) {
        if (!frameOut[vi][0].empty()) lastOut[vi] = std::move(frameOut[vi]);
      }

      // Seed 004 study (left eye, the app's own image). Runs after the filters: it reuses the
      // 1-sample render target.
      // Head-locked content is kept out of it: its motion field (Scene::motion) is the world's.
      const WarpStudyFrame studyFrame{sc.label, f, t, dt, headSpeed, objSpeed, base[0], cams[0]};
      if (scene.headLocked.empty() &&
          !writeWarpStudy(*renderer, scene, o, headAt, studyFrame, warpCsv, &error)) {
        std::cerr << "steadyxr-eval: render: " << error << "\n";
        return 1;
      }
      progress.update(++framesDone, sc.label + " " + std::to_string(f + 1) + "/" + std::to_string(o.frames));
    }
    for (size_t vi = 0; vi < variants.size(); ++vi) {
      const core::Params& p = variants[vi].params;
      if (!variants[vi].filter || !p.steadyHeadLockedSwitch || p.temporal != core::TemporalMethod::Steady)
        continue;
      if (!hudSwitchCsv.is_open()) {
        hudSwitchCsv.open(o.outDir + "/hudswitch.csv");
        hudSwitchCsv << "case,method,decided_frame\n";  // -1: never; the profile from the frame after
      }
      hudSwitchCsv << csvEscape(sc.label) << ',' << csvEscape(variants[vi].name) << ','
                   << hudSwitchedAfter[vi] << '\n';
    }
    if (detects) {
      if (!autoHudCsv.is_open()) {
        autoHudCsv.open(o.outDir + "/autohud.csv");
        autoHudCsv << kHeadLockedCsvHeader << '\n';
      }
      autoHudCsv << csvEscape(sc.label) << ',' << headLockedCsvRow(headLocked) << '\n';
    }

    // Cost: each method's frames back to back on the scenario's last frame. Interleaved with a
    // score of other methods, lavapipe's cache of compiled shaders (capped by instruction count)
    // evicts and recompiles the large temporal shaders on every frame (measured: hmtaa 13 ms
    // alone, ~600 ms interleaved at 256x256), which would be billed to the method.
    for (size_t vi = 0; vi < variants.size(); ++vi) {
      Variant& v = variants[vi];
      if (!active(v) || !lastFrame[vi] || !v.filter) continue;
      BackToBackTimes times;
      if (!timeBackToBack(*v.filter, *lastFrame[vi], *renderer, &times, &error)) {
        std::cerr << "\nsteadyxr-eval: filter '" << v.name << "' submit failed: " << error << "\n";
        return 1;
      }
      acc[vi].timedWallMs = times.wallMs;
      acc[vi].timedGpuMs = times.gpuMs;
    }

    // Rows of this scenario.
    std::vector<int> changes = motionChangeFrames(sc, *stream, headSpeeds, clock);
    addContentChangeFrames(scene, clock, &changes);  // video, fade, blink
    addChangeFrames(locomotionChangeTimes(o.locomotion, rig), clock, &changes);
    const CaseFacts facts{safeDiv(gtStereoSum, gtStereoN),
                          changes,
                          percentile(headSpeeds, 0.95),
                          rigMoves(o.locomotion),
                          !scene.hasMovingObject,
                          ctx->isCpuDevice(),
                          safeDiv(truth8TempErrSum, truth8TempErrN)};
    for (size_t vi = 0; vi < variants.size(); ++vi) {
      if (!active(variants[vi])) continue;
      rows.push_back(resultRow(sc, variants[vi], acc[vi], noneIndex >= 0 ? &acc[noneIndex] : nullptr, facts));
    }
    // Cost = the filter's GPU time + the render time above the app's render (MSAA's price).
    double baseRender = 0;
    for (const ResultRow& r : rows) {
      if (r.scenario == sc.label && r.source == o.appMsaa && r.renderMs > 0) baseRender = r.renderMs;
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
            << (o.mipmaps ? "trilinear mipmaps" : "no mipmaps")
            << (o.dropFrames > 0.0 ? ", " + std::to_string(missedPeriods(o.frames, o.dropFrames, o.seed)) +
                                         " app periods missed"
                                   : std::string())
            << ", device " << device << ", " << fmt(seconds, 4) << " s\n";
  std::cout
      << "MTCD (seed 003 Eq. 6), TempErr (temporal error vs ground truth) and StErr (per-pixel stereo error) "
         "in 8-bit code values; RMSE/SSIM vs ground truth on display-encoded [0,1]; worst/n = worst frame's "
         "RMSE / none's there; recov = most frames after a motion change until RMSE <= none's (+: not by the "
         "end); GPU = filter passes (both eyes)\n";
  printResults(rows, targets, !o.corpus);
  if (o.corpus) printCorpusTable(rows, std::cout);
  std::cout << "Outputs: " << o.outDir
            << "/results.csv, results.json, timeseries.csv, warp_errors.csv, crops/*.png"
            << (o.corpus ? ", corpus.csv" : "") << (overlayCsv.is_open() ? ", overlay.csv" : "")
            << (edgesCsv.is_open() ? ", resolved_edges.csv" : "")
            << (autoHudCsv.is_open() ? ", autohud.csv" : "")
            << (hudSwitchCsv.is_open() ? ", hudswitch.csv" : "")
            << (animateLabel.empty() ? "" : ", anim/" + animateLabel + "/") << "\n";
  if (o.validation && ctx->validationMessageCount() > 0) {
    std::cerr << "steadyxr-eval: " << ctx->validationMessageCount()
              << " validation messages, first: " << ctx->validationMessages().front() << "\n";
  }
  return 0;
}

}  // namespace steadyxr::eval
